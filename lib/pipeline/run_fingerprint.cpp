#include "pipeline/run_fingerprint.h"

#include <OpenImageIO/hash.h>

#include "pipeline/render_options.h"

#include <cstdio>
#include <type_traits>
#include <vector>

namespace qsgi {
namespace {

// Farmhash fingerprints (stable across versions and machines by design) of each part, combined
// by fingerprinting the list of part fingerprints.
class Fingerprinter {
public:
    template <class T>
    void add(const std::vector<T>& values) {
        static_assert(std::is_trivially_copyable_v<T>);
        parts_.push_back(OIIO::farmhash::Fingerprint64(reinterpret_cast<const char*>(values.data()),
                                                       values.size() * sizeof(T)));
    }
    void add(const std::string& text) { parts_.push_back(OIIO::farmhash::Fingerprint64(text.data(), text.size())); }
    template <class T>
    void addValue(const T& value) {
        add(std::vector<T>{value});
    }
    uint64_t result() const {
        return OIIO::farmhash::Fingerprint64(reinterpret_cast<const char*>(parts_.data()), parts_.size() * sizeof(uint64_t));
    }

private:
    std::vector<uint64_t> parts_;
};

}  // namespace

std::string runFingerprint(const RenderSettings& s, const Scene& scene, const std::string& animationBytes,
                           const Camera& camera) {
    Fingerprinter f;
    f.add(std::string(QSGI_VERSION));
    // The scene as loaded (rest pose), whatever files it came from.
    f.add(scene.positions);
    f.add(scene.normals);
    f.add(scene.triangles);
    f.add(scene.triangleMaterial);
    f.addValue(scene.worldOrigin);
    for (const Material& m : scene.materials) {
        f.addValue(m.albedo);
        f.addValue(m.emission);
    }
    for (const PunctualLight& l : scene.lights) {
        f.addValue(int(l.type));
        f.addValue(l.position);
        f.addValue(l.direction);
        f.addValue(l.intensity);
        f.addValue(l.cosOuterCone);
    }
    f.add(animationBytes);
    // Every option that reaches the frame files, as the option table declares them (the scene's
    // path among them: EXR metadata names it).
    f.add(optionValues(s, OptionSelection::Fingerprinted).dump());
    f.addValue(camera.position);
    f.addValue(camera.forward);
    f.addValue(camera.up);
    f.addValue(camera.yfov);
    f.addValue(int(camera.projection));
    f.addValue(camera.ymag);
    f.addValue(camera.node);
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(f.result()));
    return hex;
}

}  // namespace qsgi
