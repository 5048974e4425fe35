#include "pipeline/render_settings.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "util/error.h"
#include "util/json_file.h"
#include "util/memory.h"
#include "pipeline/render_options.h"

namespace qsgi {

using nlohmann::json;

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

void applyConfigFile(const std::string& path, RenderSettings& s) { applyConfigJson(path, readJsonFile(path), s); }

void applyConfigJson(const std::string& path, const nlohmann::json& doc, RenderSettings& s) {
    s.configPath = path;
    if (!doc.is_object()) throw InputError(path, "", "must be a JSON object");
    std::vector<std::string> keys;
    for (const RenderOption& o : renderOptions())
        if (o.key) keys.push_back(o.key);
    refuseUnknownKeys(doc, keys, path, "");
    OptionSource source{path, "", std::filesystem::path(path).parent_path()};
    try {
        for (auto it = doc.begin(); it != doc.end(); ++it) {
            // Any other key is a note for people ("_…", "comment"): refuseUnknownKeys let it through.
            const RenderOption* option = optionWithKey(it.key());
            if (!option) continue;
            source.place = it.key();
            applyOption(*option, it.value(), source, s);
        }
    } catch (const json::exception& e) {
        throw InputError(path, source.place, std::string("has the wrong JSON type (") + e.what() + ")");
    }
}

TraceSettings effectiveTrace(const TraceSettings& trace) {
    TraceSettings t = trace;
    PhotonSampling& sampling = t.sampling;
    sampling.qmcBounces = sampling.kind == SamplerKind::Random ? 0 : std::min({sampling.qmcBounces, t.maxBounces, kMaxQmcBounces});
    return t;
}

void validateSettings(const RenderSettings& s) {
    // Values from a config or the command line were checked as they were read, naming their
    // source; this catches a program that fills RenderSettings itself, by the same rules.
    for (const RenderOption& o : renderOptions()) {
        if (!o.key || !o.get || o.type == OptionType::Object) continue;
        const json value = o.get(s);
        if (value.is_null()) continue;
        RenderSettings scratch = s;
        applyOption(o, value, {"settings", o.key, {}}, scratch);
    }
    if (s.scenePath.empty()) throw InputError("command line", "SCENE", "no scene given");
    // Checked after the config and the command line are merged: the bound is max_bounces.
    if (s.qmcBouncesGiven && s.trace.sampling.kind == SamplerKind::Sobol)  // K means nothing under random
        checkedInteger(s.trace.sampling.qmcBounces, 0, std::min<int64_t>(s.trace.maxBounces, kMaxQmcBounces),
                       s.configPath.empty() ? "command line" : s.configPath + " or the command line", "qmc_bounces",
                       " (at most max_bounces, and the Sobol table covers 32 scatterings)");
    // The gather replaces the estimate of indirect light only; with direct light from the photons
    // there is nothing apart for it to add to.
    if (s.gatherGiven && s.lighting.gatherRays > 0 && !s.lighting.exactDirect())
        throw InputError(s.configPath.empty() ? "command line" : s.configPath + " or the command line", "gather",
                         std::to_string(s.lighting.gatherRays) +
                             " gather rays need --direct exact (the gather adds one bounce over the photons to exact "
                             "direct light); give --gather 0 with --direct photons");
}

}  // namespace qsgi
