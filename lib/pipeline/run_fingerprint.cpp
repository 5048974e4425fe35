#include "pipeline/run_fingerprint.h"

#include <OpenImageIO/hash.h>

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
    f.add(s.scenePath);  // EXR metadata names it
    // Settings that reach the frame files.
    const EstimatorSettings& e = s.estimator;
    f.add(std::vector<int64_t>{int64_t(e.kind), int64_t(e.k), int64_t(e.useIndex), int64_t(e.sortQueries),
                               int64_t(e.detpIndex), int64_t(e.boundary), int64_t(s.photons), int64_t(s.seed),
                               int64_t(s.maxBounces), s.width, s.height, s.samplesPerPixel, int64_t(s.writeExr),
                               int64_t(s.exrHalf), int64_t(s.writePng), int64_t(s.exposure.has_value()),
                               int64_t(s.writeGltf), int64_t(s.aimEmission), int64_t(s.sampling.kind),
                               // The K that shapes the bytes: none under random, capped at max_bounces.
                               int64_t(effectiveSampling(s).qmcBounces)});
    f.addValue(e.radius);
    f.addValue(s.exposure.value_or(0.0f));
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
