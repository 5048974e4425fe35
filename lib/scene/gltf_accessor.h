// glTF accessors as numbers (glTF 2.0 §3.6–3.7): an accessor's elements decoded to doubles, with
// every rule the specification sets on them checked (element type and component types for the
// use, normalisation, buffer-view ranges, strides and alignment, sparse substitution) before any
// byte is read. The scene loader and the animation reader both read through it.
#pragma once

#include <tiny_gltf.h>

#include <set>
#include <string>
#include <utility>
#include <vector>

#include "scene/gltf_document.h"

namespace qsgi {

// "what[index]": a place in a glTF document, for messages.
std::string gltfPlace(const std::string& what, int index);

// What the glTF 2.0 specification (§3.7.2.1, and KHR_mesh_quantization when the file requires it)
// allows for the accessors qsgi reads: their element type, component types and normalisation.
struct AccessorFormat {
    int type;  // TINYGLTF_TYPE_*
    std::vector<std::pair<int, bool>> allowed;           // (componentType, normalized)
    std::vector<std::pair<int, bool>> allowedQuantized;  // more, with KHR_mesh_quantization
};

// The Khronos glTF-Validator's tolerances (read from its source), which qsgi applies to the same
// rules: |length − 1| of unit vectors (normals) and of rotation quaternions.
constexpr double kUnitVectorTolerance = 0.00674;
constexpr double kUnitQuaternionTolerance = 0.00769;

// "FLOAT", "UNSIGNED_SHORT", …
std::string componentTypeName(int type);

// An accessor's elements as doubles, `components` per element, normalised integers mapped to
// [0,1] or [-1,1] as the glTF spec says. Every offset is bounds-checked against its buffer, and
// sizes against the machine's memory, before anything is allocated.
struct AccessorData {
    size_t count = 0;
    int components = 0;
    std::vector<double> values;
    double operator()(size_t element, int component) const { return values[element * components + component]; }
};

// Reads accessors for one document, with the checks above. `file` names the document in messages.
class AccessorReader {
public:
    AccessorReader(const GltfDocument& document, const std::string& file);

    // The accessor's elements, checked against `format`; `usedBy` names the referring place.
    // Throws InputError naming the file and the place.
    AccessorData read(int accessorIndex, const std::string& usedBy, const AccessorFormat& format) const;
    // The same, leaving the check of the accessor's declared min and max to the caller
    // (checkDeclaredBounds), who has a more telling check to run first (indices beyond the
    // vertices).
    AccessorData readUnbounded(int accessorIndex, const std::string& usedBy, const AccessorFormat& format) const;
    // The accessor's min and max, where given, against its elements (glTF 2.0 §3.6.2.5).
    void checkDeclaredBounds(int accessorIndex, const AccessorData& data, const std::string& usedBy) const;

    // Checks an accessor nothing reads as read() would check its layout (it exists, its type
    // and componentType are known, its elements and sparse parts lie inside their views and
    // buffers) and, where the file holds its data, decodes it to check its values.
    void checkUnread(int accessorIndex, const std::string& usedBy) const;
    // The same for a buffer view nothing reads: inside its buffer, a stride glTF allows.
    void checkUnreadView(int viewIndex) const;
    // Whether the accessor's elements are stated in the file: a bufferView into a buffer with
    // data, or sparse values. Otherwise they are zeros by default, and data-level rules (bounds,
    // unit normals, weights summing to 1) have nothing to judge, as for the glTF-Validator.
    bool hasData(int accessorIndex) const;
    // While set, a read through a buffer without data (no uri) gives zeros instead of an error:
    // for checking objects nothing reads, where such buffers are valid (the loader's
    // checkUnusedObjects).
    void tolerateAbsentData(bool tolerate) const { tolerateAbsent_ = tolerate; }
    // Whether read() was called for the accessor (whatever it found) since forgetReads(): the
    // loader asks before it checks the unread ones, so this is what the render used.
    void forgetReads() const {
        read_.clear();
        viewsRead_.clear();
    }
    bool wasRead(int accessorIndex) const { return read_.count(accessorIndex) > 0; }
    // Whether a read went through the buffer view (an accessor's, an embedded image's).
    bool viewWasRead(int viewIndex) const { return viewsRead_.count(viewIndex) > 0; }

    // The bytes of a whole buffer view (an embedded image, say), after checking that the view and
    // its buffer exist and that the view lies inside the buffer. `usedBy` names the referring place.
    struct Bytes {
        const unsigned char* data = nullptr;
        size_t size = 0;
    };
    Bytes viewBytes(int viewIndex, const std::string& usedBy) const;

private:
    // The view, checked as viewBytes checks it. needData false: a view into a buffer without
    // data (no uri) passes, since nothing reads it (checkUnread).
    const tinygltf::BufferView& checkedView(int viewIndex, const std::string& place, bool needData = true) const;
    void checkFormat(const tinygltf::Accessor& acc, const AccessorFormat& format, const std::string& place) const;
    // A view's byteStride: none, or a multiple of 4 in 4..252.
    void checkStride(const tinygltf::BufferView& view, int viewIndex) const;
    // The elements' and the sparse parts' ranges, the sparse count and index type.
    void checkLayout(const tinygltf::Accessor& acc, int components, const std::string& place, bool needData = true) const;
    // Checks that `count` elements from a buffer view lie inside the view and its buffer, with
    // the alignment and stride the specification requires.
    void checkRange(int viewIndex, size_t byteOffset, size_t count, int componentType, int components,
                    const std::string& place, bool needData = true) const;
    // Decodes `count` elements (checked by checkRange) into `doubles` or, for sparse indices,
    // into `indices`.
    void decode(int viewIndex, size_t byteOffset, size_t count, int componentType, bool normalized, int components,
                double* doubles, std::vector<size_t>* indices) const;
    static double component(const unsigned char* p, int type, bool normalized);
    void applySparse(const tinygltf::Accessor& acc, AccessorData& out, const std::string& place) const;

    const tinygltf::Model& model_;
    const std::set<int>& absentBuffers_;
    std::string file_;
    bool quantized_ = false;
    mutable std::set<int> read_, viewsRead_;
    mutable bool tolerateAbsent_ = false;
    bool viewHasData(int viewIndex) const;
};

}  // namespace qsgi
