#include "pipeline/render_settings.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"
#include "util/memory.h"

namespace qsgi {

int64_t checkedInteger(int64_t value, int64_t lo, int64_t hi, const std::string& source, const std::string& place,
                       const std::string& why) {
    if (value < lo || value > hi)
        throw InputError(source, place, std::to_string(value) + " is outside " + std::to_string(lo) + ".." +
                                            std::to_string(hi) + why);
    return value;
}

uint64_t checkedPhotons(int64_t value, const std::string& source, const std::string& place) {
    const uint64_t photons = uint64_t(checkedInteger(value, 1, kMaxPhotons, source, place, " (2^32: the path index is 32 bits)"));
    refuseBeyondMemory(photons * kLeastBytesPerPhoton, source, place,
                       std::to_string(photons) + " photons (at least " + std::to_string(kLeastBytesPerPhoton) +
                           " bytes each in the ray cache)");
    return photons;
}

std::optional<int> gltfAnimationSelector(const std::string& animation, const std::string& source) {
    if (animation == "gltf") return -1;
    if (animation.rfind("gltf:", 0) != 0) return std::nullopt;
    const std::string digits = animation.substr(5);
    if (digits.empty() || digits.size() > 6 || digits.find_first_not_of("0123456789") != std::string::npos)
        throw InputError(source, "animation", "'" + animation + "' is not gltf or gltf:N with N a glTF animation index");
    return std::stoi(digits);
}

float defaultRadius(const Bounds3f& animationBounds) { return kDefaultRadiusFraction * std::max(animationBounds.extent(), 1e-6f); }
float defaultRadius(const Scene& scene) { return defaultRadius(scene.animationBounds); }


FrameRange parseFrameRange(const std::string& text, const std::string& source) {
    auto parseInt = [&](const std::string& s) {
        if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos)
            throw InputError(source, "frames", "'" + text + "' is not A:B with non-negative integers A <= B");
        return std::stoi(s);
    };
    FrameRange r;
    const auto colon = text.find(':');
    if (colon == std::string::npos) {
        r.first = r.last = parseInt(text);
    } else {
        r.first = parseInt(text.substr(0, colon));
        r.last = parseInt(text.substr(colon + 1));
    }
    if (r.first > r.last) throw InputError(source, "frames", "'" + text + "': the first frame is after the last");
    return r;
}

TraceSettings effectiveTrace(const TraceSettings& trace) {
    TraceSettings t = trace;
    PhotonSampling& sampling = t.sampling;
    sampling.qmcBounces = sampling.kind == SamplerKind::Random ? 0 : std::min({sampling.qmcBounces, t.maxBounces, kMaxQmcBounces});
    return t;
}

}  // namespace qsgi
