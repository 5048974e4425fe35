#include "scene/gltf_accessor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "util/error.h"
#include "util/memory.h"

namespace qsgi {

std::string gltfPlace(const std::string& what, int index) { return what + "[" + std::to_string(index) + "]"; }

namespace {
// A normalised integer component's value (glTF 2.0 §3.11): its raw value over the type's
// largest, signed ones clamped at −1.
double normalised(double raw, int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return std::max(raw / 127.0, -1.0);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return raw / 255.0;
        case TINYGLTF_COMPONENT_TYPE_SHORT: return std::max(raw / 32767.0, -1.0);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return raw / 65535.0;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return raw / 4294967295.0;
        default: return raw;
    }
}

std::string typeName(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return "SCALAR";
        case TINYGLTF_TYPE_VEC2: return "VEC2";
        case TINYGLTF_TYPE_VEC3: return "VEC3";
        case TINYGLTF_TYPE_VEC4: return "VEC4";
        case TINYGLTF_TYPE_MAT4: return "MAT4";
        default: return "type " + std::to_string(type);
    }
}
}  // namespace

std::string componentTypeName(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
        default: return "componentType " + std::to_string(type);
    }
}

AccessorReader::AccessorReader(const GltfDocument& document, const std::string& file)
    : model_(document.model), absentBuffers_(document.absentBuffers), file_(file) {
    for (const auto& ext : model_.extensionsRequired) quantized_ = quantized_ || ext == "KHR_mesh_quantization";
}

AccessorData AccessorReader::read(int accessorIndex, const std::string& usedBy, const AccessorFormat& format) const {
    AccessorData out = readUnbounded(accessorIndex, usedBy, format);
    checkDeclaredBounds(accessorIndex, out, usedBy);
    return out;
}

AccessorData AccessorReader::readUnbounded(int accessorIndex, const std::string& usedBy, const AccessorFormat& format) const {
    const std::string place = usedBy + " -> " + gltfPlace("accessors", accessorIndex);
    if (accessorIndex < 0 || accessorIndex >= int(model_.accessors.size()))
        throw InputError(file_, usedBy, "refers to accessor " + std::to_string(accessorIndex) +
                                            ", which does not exist");
    read_.insert(accessorIndex);
    const tinygltf::Accessor& acc = model_.accessors[accessorIndex];
    checkFormat(acc, format, place);
    AccessorData out;
    out.count = acc.count;
    out.components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
    refuseBeyondMemory(saturatingMultiply(acc.count, uint64_t(out.components) * sizeof(double)), file_, place,
                       "its " + std::to_string(acc.count) + " elements");
    checkLayout(acc, out.components, place);
    out.values.assign(acc.count * size_t(out.components), 0.0);
    // Without a bufferView the elements are zeros, typically overridden by sparse values.
    if (acc.bufferView >= 0)
        decode(acc.bufferView, acc.byteOffset, acc.count, acc.componentType, acc.normalized, out.components,
               out.values.data(), nullptr);
    if (acc.sparse.isSparse) applySparse(acc, out, place);
    for (double v : out.values)
        if (!std::isfinite(v)) throw InputError(file_, place, "holds a non-finite number (NaN or Inf)");
    return out;
}

void AccessorReader::checkDeclaredBounds(int accessorIndex, const AccessorData& data, const std::string& usedBy) const {
    const tinygltf::Accessor& acc = model_.accessors[size_t(accessorIndex)];
    const std::string place = usedBy + " -> " + gltfPlace("accessors", accessorIndex);
    const int components = data.components;
    // An accessor without a bufferView or sparse values holds zeros only by default: like the
    // glTF-Validator, which has no elements to compare, its bounds are taken as given.
    if (!hasData(accessorIndex)) return;
    if (data.count == 0) return;
    // glTF 2.0 (§3.6.2.5): min and max, where given, are the elements' exact bounds, per component,
    // in the components' own type (a normalised integer's raw value). They are compared here
    // after the same normalisation, with a relative 10^-5 for the decimal digits a float loses.
    for (const auto* bound : {&acc.minValues, &acc.maxValues}) {
        if (bound->empty()) continue;
        if (int(bound->size()) != components)
            throw InputError(file_, place, std::string(bound == &acc.minValues ? "min" : "max") + " has " +
                                               std::to_string(bound->size()) + " numbers for " + std::to_string(components) +
                                               " components");
    }
    if (acc.minValues.empty() && acc.maxValues.empty()) return;
    auto text = [](double v) {
        char out[32];
        std::snprintf(out, sizeof out, "%.9g", v);
        return std::string(out);
    };
    for (int c = 0; c < components; ++c) {
        double lowest = data(0, c), highest = data(0, c);
        for (size_t e = 1; e < data.count; ++e) {
            lowest = std::min(lowest, data(e, c));
            highest = std::max(highest, data(e, c));
        }
        const double tolerance = 1e-5 * std::max({std::fabs(lowest), std::fabs(highest), 1e-30});
        auto differs = [&](double declared, double actual) {
            return std::fabs((acc.normalized ? normalised(declared, acc.componentType) : declared) - actual) > tolerance;
        };
        if (!acc.minValues.empty() && differs(acc.minValues[size_t(c)], lowest))
            throw InputError(file_, place + ".min", "component " + std::to_string(c) + " is declared " +
                                                        text(acc.minValues[size_t(c)]) + " but the elements' least is " +
                                                        text(lowest) + " (glTF requires the exact bounds)");
        if (!acc.maxValues.empty() && differs(acc.maxValues[size_t(c)], highest))
            throw InputError(file_, place + ".max", "component " + std::to_string(c) + " is declared " +
                                                        text(acc.maxValues[size_t(c)]) + " but the elements' greatest is " +
                                                        text(highest) + " (glTF requires the exact bounds)");
    }
}

bool AccessorReader::viewHasData(int viewIndex) const {
    return viewIndex >= 0 && viewIndex < int(model_.bufferViews.size()) &&
           !absentBuffers_.count(model_.bufferViews[size_t(viewIndex)].buffer);
}

bool AccessorReader::hasData(int accessorIndex) const {
    if (accessorIndex < 0 || accessorIndex >= int(model_.accessors.size())) return false;
    const tinygltf::Accessor& acc = model_.accessors[size_t(accessorIndex)];
    return viewHasData(acc.bufferView) || (acc.sparse.isSparse && viewHasData(acc.sparse.indices.bufferView) &&
                                           viewHasData(acc.sparse.values.bufferView));
}

void AccessorReader::checkUnread(int accessorIndex, const std::string& usedBy) const {
    if (accessorIndex < 0 || accessorIndex >= int(model_.accessors.size()))
        throw InputError(file_, usedBy, "refers to accessor " + std::to_string(accessorIndex) + ", which does not exist");
    const tinygltf::Accessor& acc = model_.accessors[size_t(accessorIndex)];
    const int components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
    if (components <= 0 || tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType)) <= 0)
        throw InputError(file_, usedBy, "unknown accessor type or componentType");
    checkLayout(acc, components, usedBy, false);
    // As what it says it is (checkFormat's rules hold for any format) and, with data to read,
    // finite and within its stated bounds.
    const AccessorFormat itself{acc.type, {{acc.componentType, acc.normalized}}, {}};
    checkFormat(acc, itself, usedBy);
    if (hasData(accessorIndex)) read(accessorIndex, usedBy, itself);
}

void AccessorReader::checkStride(const tinygltf::BufferView& view, int viewIndex) const {
    if (view.byteStride != 0 && (view.byteStride < 4 || view.byteStride > 252 || view.byteStride % 4 != 0))
        throw InputError(file_, gltfPlace("bufferViews", viewIndex) + ".byteStride",
                         std::to_string(view.byteStride) + " is not a multiple of 4 in 4..252");
}

void AccessorReader::checkUnreadView(int viewIndex) const {
    const tinygltf::BufferView& view = checkedView(viewIndex, gltfPlace("bufferViews", viewIndex), false);
    checkStride(view, viewIndex);
    if (view.byteStride > view.byteLength)
        throw InputError(file_, gltfPlace("bufferViews", viewIndex) + ".byteStride",
                         std::to_string(view.byteStride) + " exceeds the view's byteLength " + std::to_string(view.byteLength));
    if (view.byteStride != 0 && view.target == TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER)
        throw InputError(file_, gltfPlace("bufferViews", viewIndex) + ".byteStride",
                         "is set on a view of indices (target 34963), which glTF forbids");
}

void AccessorReader::checkLayout(const tinygltf::Accessor& acc, int components, const std::string& place, bool needData) const {
    if (acc.bufferView >= 0)
        checkRange(acc.bufferView, acc.byteOffset, acc.count, acc.componentType, components, place, needData);
    if (!acc.sparse.isSparse) return;
    if (acc.sparse.count < 1 || size_t(acc.sparse.count) > acc.count)
        throw InputError(file_, place + ".sparse.count", std::to_string(acc.sparse.count) +
                                                             " is outside 1..count of the accessor");
    const size_t n = size_t(acc.sparse.count);
    const int indexType = acc.sparse.indices.componentType;
    if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        throw InputError(file_, place + ".sparse.indices.componentType", "must be an unsigned integer type");
    checkRange(acc.sparse.indices.bufferView, size_t(acc.sparse.indices.byteOffset), n, indexType, 1,
               place + ".sparse.indices", needData);
    checkRange(acc.sparse.values.bufferView, size_t(acc.sparse.values.byteOffset), n, acc.componentType, components,
               place + ".sparse.values", needData);
}

void AccessorReader::checkFormat(const tinygltf::Accessor& acc, const AccessorFormat& format, const std::string& place) const {
    const int components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
    if (components <= 0 || tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType)) <= 0)
        throw InputError(file_, place, "unknown accessor type or componentType");
    // glTF 2.0 (§3.6.2.2): "normalized" applies to 8- and 16-bit integers only.
    if (acc.normalized && (acc.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                           acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        throw InputError(file_, place + ".normalized", "is true for " + componentTypeName(acc.componentType) +
                                                           " components (glTF allows it for 8- and 16-bit integers only)");
    if (acc.type != format.type)
        throw InputError(file_, place, "must be of type " + typeName(format.type));
    const std::pair<int, bool> used{acc.componentType, acc.normalized};
    auto allows = [&](const std::vector<std::pair<int, bool>>& list) {
        return std::find(list.begin(), list.end(), used) != list.end();
    };
    if (allows(format.allowed) || (quantized_ && allows(format.allowedQuantized))) return;
    const std::string what = (acc.normalized ? "normalized " : "") + componentTypeName(acc.componentType);
    if (allows(format.allowedQuantized))
        throw InputError(file_, place, what + " components need the KHR_mesh_quantization extension, which the "
                                              "file does not list in extensionsRequired");
    throw InputError(file_, place, what + " components are not allowed here by the glTF 2.0 specification");
}

const tinygltf::BufferView& AccessorReader::checkedView(int viewIndex, const std::string& place, bool needData) const {
    if (viewIndex < 0 || viewIndex >= int(model_.bufferViews.size()))
        throw InputError(file_, place, "refers to bufferView " + std::to_string(viewIndex) + ", which does not exist");
    const std::string viewPlace = gltfPlace("bufferViews", viewIndex);
    if (needData) viewsRead_.insert(viewIndex);
    const tinygltf::BufferView& view = model_.bufferViews[viewIndex];
    if (view.buffer < 0 || view.buffer >= int(model_.buffers.size()))
        throw InputError(file_, viewPlace, "refers to a buffer that does not exist");
    if (view.byteLength == 0) throw InputError(file_, viewPlace + ".byteLength", "is 0 (glTF requires at least 1)");
    if (absentBuffers_.count(view.buffer) && (!needData || tolerateAbsent_)) return view;
    if (absentBuffers_.count(view.buffer))
        throw InputError(file_, viewPlace, "reads buffer " + std::to_string(view.buffer) +
                                               ", which has no uri and so no data");
    const tinygltf::Buffer& buffer = model_.buffers[view.buffer];
    const uint64_t end = saturatingAdd(view.byteOffset, view.byteLength);
    if (end > buffer.data.size())
        throw InputError(file_, viewPlace,
                         "reaches byte " + (end == UINT64_MAX ? std::string("2^64 or beyond") : std::to_string(end)) +
                             " of buffer " + std::to_string(view.buffer) + ", which holds only " +
                             std::to_string(buffer.data.size()));
    return view;
}

AccessorReader::Bytes AccessorReader::viewBytes(int viewIndex, const std::string& usedBy) const {
    const tinygltf::BufferView& view = checkedView(viewIndex, usedBy);
    return {model_.buffers[view.buffer].data.data() + view.byteOffset, view.byteLength};
}

void AccessorReader::checkRange(int viewIndex, size_t byteOffset, size_t count, int componentType, int components,
                const std::string& place, bool needData) const {
    const tinygltf::BufferView& view = checkedView(viewIndex, place, needData);
    const std::string viewPlace = gltfPlace("bufferViews", viewIndex);
    const uint64_t componentSize = uint64_t(tinygltf::GetComponentSizeInBytes(uint32_t(componentType)));
    const uint64_t elementSize = componentSize * uint64_t(components);
    checkStride(view, viewIndex);
    if (view.byteStride != 0 && view.byteStride < elementSize)
        throw InputError(file_, viewPlace + ".byteStride", std::to_string(view.byteStride) + " is smaller than the " +
                                                               std::to_string(elementSize) + "-byte elements of " + place);
    if (byteOffset % componentSize != 0 || (view.byteOffset + byteOffset) % componentSize != 0)
        throw InputError(file_, place, "byteOffset is not a multiple of its " + std::to_string(componentSize) +
                                           "-byte component size");
    const uint64_t stride = view.byteStride ? view.byteStride : elementSize;
    if (count > 0 && saturatingAdd(saturatingAdd(byteOffset, saturatingMultiply(stride, count - 1)), elementSize) >
                         view.byteLength)
        throw InputError(file_, place, "reads past the end of bufferView " + std::to_string(viewIndex));
}

void AccessorReader::decode(int viewIndex, size_t byteOffset, size_t count, int componentType, bool normalized,
            int components, double* doubles, std::vector<size_t>* indices) const {
    if (!viewHasData(viewIndex)) {  // tolerated (tolerateAbsentData): zeros
        if (indices) indices->assign(count, 0);
        return;
    }
    const tinygltf::BufferView& view = model_.bufferViews[viewIndex];
    const tinygltf::Buffer& buffer = model_.buffers[view.buffer];
    const size_t componentSize = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(componentType)));
    const size_t elementSize = componentSize * size_t(components);
    const size_t stride = view.byteStride ? view.byteStride : elementSize;
    const unsigned char* base = buffer.data.data() + view.byteOffset + byteOffset;
    for (size_t e = 0; e < count; ++e) {
        const unsigned char* element = base + e * stride;
        for (int c = 0; c < components; ++c) {
            const double v = component(element + c * componentSize, componentType, normalized);
            if (indices) (*indices)[e] = size_t(v);
            else doubles[e * components + c] = v;
        }
    }
}

double AccessorReader::component(const unsigned char* p, int type, bool normalized) {
    double raw = 0;
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: { int8_t v; std::memcpy(&v, p, 1); raw = v; break; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { uint8_t v; std::memcpy(&v, p, 1); raw = v; break; }
        case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t v; std::memcpy(&v, p, 2); raw = v; break; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); raw = v; break; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t v; std::memcpy(&v, p, 4); raw = v; break; }
        case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p, 4); return v; }
        default: return 0;
    }
    return normalized ? normalised(raw, type) : raw;
}

void AccessorReader::applySparse(const tinygltf::Accessor& acc, AccessorData& out, const std::string& place) const {
    // checkLayout has checked the count, the index type and both ranges. Sparse parts in a
    // buffer without data (only read while tolerated) change nothing.
    if (!viewHasData(acc.sparse.indices.bufferView) || !viewHasData(acc.sparse.values.bufferView)) return;
    const size_t n = size_t(acc.sparse.count);
    const int indexType = acc.sparse.indices.componentType;
    std::vector<size_t> targets(n);
    decode(acc.sparse.indices.bufferView, size_t(acc.sparse.indices.byteOffset), n, indexType, false, 1, nullptr,
           &targets);
    std::vector<double> values(n * size_t(out.components));
    decode(acc.sparse.values.bufferView, size_t(acc.sparse.values.byteOffset), n, acc.componentType,
           acc.normalized, out.components, values.data(), nullptr);
    for (size_t i = 0; i < n; ++i) {
        if (targets[i] >= out.count)
            throw InputError(file_, place + ".sparse.indices", "index " + std::to_string(targets[i]) +
                                                                   " is beyond the accessor's count");
        if (i > 0 && targets[i] <= targets[i - 1])
            throw InputError(file_, place + ".sparse.indices", "must strictly increase (index " +
                                                                   std::to_string(targets[i]) + " follows " +
                                                                   std::to_string(targets[i - 1]) + ")");
        for (int c = 0; c < out.components; ++c) out.values[targets[i] * out.components + c] = values[i * out.components + c];
    }
}

}  // namespace qsgi
