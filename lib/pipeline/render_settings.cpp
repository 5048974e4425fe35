#include "pipeline/render_settings.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "util/error.h"
#include "trace/ray_cache.h"
#include "util/json_file.h"
#include "util/memory.h"
#include "util/nearest_name.h"

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
    refuseBeyondMemory(photons * RayCache::kBytesPerPath, source, place,
                       std::to_string(photons) + " photons (at least " + std::to_string(RayCache::kBytesPerPath) +
                           " bytes each in the ray cache)");
    return photons;
}

uint32_t checkedQmcBounces(int64_t value, const std::string& source, const std::string& place) {
    return uint32_t(checkedInteger(value, 0, kMaxQmcBounces, source, place, " (the Sobol table covers that many scatterings)"));
}

EstimatorKind parseEstimator(const std::string& name, const std::string& source) {
    if (name == "impact-count") return EstimatorKind::ImpactCount;
    if (name == "photon-map") return EstimatorKind::PhotonMap;
    if (name == "detp") return EstimatorKind::Detp;
    throw InputError(source, "estimator", "unknown estimator '" + name + "'" +
                                              didYouMean(name, {"detp", "photon-map", "impact-count"}) +
                                              " (available: detp, photon-map, impact-count)");
}

DetpIndex parseDetpIndex(const std::string& name, const std::string& source) {
    if (name == "embree") return DetpIndex::Embree;
    if (name == "flann") return DetpIndex::Flann;
    throw InputError(source, "detp_index", "unknown DETP index '" + name + "' (embree: exact, flann: approximate)");
}

DetpBoundary parseDetpBoundary(const std::string& name, const std::string& source) {
    if (name == "clip") return DetpBoundary::Clip;
    if (name == "linear") return DetpBoundary::Linear;
    if (name == "paper") return DetpBoundary::Paper;
    throw InputError(source, "detp_boundary",
                     "unknown boundary rule '" + name + "' (clip: default, linear: first-order edge correction, paper: the published rule)");
}

SamplerKind parseSampler(const std::string& name, const std::string& source) {
    if (name == "sobol") return SamplerKind::Sobol;
    if (name == "random") return SamplerKind::Random;
    throw InputError(source, "sampler",
                     "unknown sampler '" + name + "' (sobol: scrambled Sobol points, the default; random: hashed numbers)");
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

double checkedFps(double fps, const std::string& file, const std::string& place) {
    if (!(fps > 0) || !(fps <= 1e6)) throw InputError(file, place, "must be a positive number of frames per second (at most 10^6)");
    return fps;
}

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

namespace {

Vec3f vec3(const json& j, const std::string& file, const std::string& place) {
    if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
        throw InputError(file, place, "must be an array of 3 numbers");
    Vec3f v(j[0].get<float>(), j[1].get<float>(), j[2].get<float>());
    if (!isFinite(v)) throw InputError(file, place, "holds a non-finite number");
    return v;
}

// An integer, also when written as 1e6 (a float with no fraction); never wrapped.
int64_t jsonInteger(const json& v, const std::string& file, const std::string& key) {
    if (v.is_number_unsigned()) return v.get<uint64_t>() > uint64_t(INT64_MAX) ? INT64_MAX : int64_t(v.get<uint64_t>());
    if (v.is_number_integer()) return v.get<int64_t>();
    if (v.is_number_float()) {
        const double d = v.get<double>();
        if (std::floor(d) == d && std::fabs(d) < 9.0e18) return int64_t(d);
    }
    throw InputError(file, key, "must be an integer");
}

PunctualLight parseLight(const json& j, const std::string& file, const std::string& place) {
    if (!j.is_object() || !j.contains("type") || !j["type"].is_string())
        throw InputError(file, place, "must be an object with a \"type\" (point or directional)");
    refuseUnknownKeys(j, {"type", "position", "intensity", "direction", "irradiance", "name"}, file, place);
    PunctualLight l;
    const std::string type = j["type"];
    l.name = place;
    auto nonNegative = [&](const Vec3f& v, const std::string& field) {
        if (v.x < 0 || v.y < 0 || v.z < 0) throw InputError(file, place + "." + field, "must be non-negative");
        return v;
    };
    if (type == "point") {
        l.type = LightType::Point;
        if (!j.contains("position") || !j.contains("intensity"))
            throw InputError(file, place, "a point light needs \"position\" and \"intensity\" (W/sr)");
        l.position = vec3(j["position"], file, place + ".position");
        l.intensity = nonNegative(vec3(j["intensity"], file, place + ".intensity"), "intensity");
    } else if (type == "directional") {
        l.type = LightType::Directional;
        if (!j.contains("direction") || !j.contains("irradiance"))
            throw InputError(file, place, "a directional light needs \"direction\" and \"irradiance\" (W/m^2)");
        l.direction = normalize(vec3(j["direction"], file, place + ".direction"));
        if (dot(l.direction, l.direction) == 0) throw InputError(file, place + ".direction", "must not be zero");
        l.intensity = nonNegative(vec3(j["irradiance"], file, place + ".irradiance"), "irradiance");
    } else {
        throw InputError(file, place + ".type", "unknown light type '" + type + "' (point or directional)");
    }
    return l;
}

const std::vector<std::string> kConfigKeys = {
    "scene", "animation", "fps", "out", "estimator", "radius", "k", "ray_cache", "sort_queries", "full_recompute", "always_update",
    "envelope", "aim_emission", "blocking_grid", "detp_index", "detp_boundary", "photons", "seed", "max_bounces", "sampler", "qmc_bounces", "threads",
    "frames", "lights", "width", "height", "spp", "exr", "exr_half", "png", "gltf_out", "exposure", "camera"};

void applyConfig(const std::string& path, const json& doc, RenderSettings& s);
}  // namespace

void applyConfigFile(const std::string& path, RenderSettings& s) { applyConfigJson(path, readJsonFile(path), s); }

void applyConfigJson(const std::string& path, const nlohmann::json& doc, RenderSettings& s) {
    s.configPath = path;
    try {
        applyConfig(path, doc, s);
    } catch (const json::exception& e) {
        throw InputError(path, "", std::string("a field has the wrong JSON type (") + e.what() + ")");
    }
}

namespace {
void applyConfig(const std::string& path, const json& doc, RenderSettings& s) {
    if (!doc.is_object()) throw InputError(path, "", "must be a JSON object");
    refuseUnknownKeys(doc, kConfigKeys, path, "");
    const std::filesystem::path base = std::filesystem::path(path).parent_path();
    auto resolve = [&](const std::string& p) { return std::filesystem::path(p).is_absolute() ? p : (base / p).string(); };
    for (auto it = doc.begin(); it != doc.end(); ++it) {
        const std::string& key = it.key();
        const json& v = it.value();
        auto str = [&]() {
            if (!v.is_string()) throw InputError(path, key, "must be a string");
            return v.get<std::string>();
        };
        if (key == "scene") s.scenePath = resolve(str());
        else if (key == "animation") {
            s.animationPath = str();
            if (!gltfAnimationSelector(s.animationPath, path)) s.animationPath = resolve(s.animationPath);
        } else if (key == "fps") {
            s.fps = checkedFps(v.is_number() ? v.get<double>() : 0.0, path, key);
        }
        else if (key == "out") s.outDir = str();
        else if (key == "estimator") s.estimator.kind = parseEstimator(str(), path);
        else if (key == "radius") {
            if (!v.is_number() || !(v.get<double>() > 0) || !std::isfinite(v.get<double>()))
                throw InputError(path, key, "must be a positive number (scene units)");
            s.estimator.radius = v.get<float>();
            s.radiusGiven = true;
        } else if (key == "k") s.estimator.k = int(checkedInteger(jsonInteger(v, path, key), 1, kMaxK, path, key));
        else if (key == "ray_cache" || key == "sort_queries" || key == "full_recompute" || key == "envelope" ||
                 key == "aim_emission" || key == "blocking_grid" || key == "always_update") {
            if (!v.is_boolean()) throw InputError(path, key, "must be true or false");
            bool& target = key == "ray_cache" ? s.estimator.useIndex
                           : key == "sort_queries" ? s.estimator.sortQueries
                           : key == "full_recompute" ? s.fullRecompute
                           : key == "envelope"       ? s.useEnvelope
                           : key == "aim_emission"   ? s.aimEmission
                           : key == "always_update"  ? s.alwaysUpdate
                                                     : s.blockingGrid;
            target = v.get<bool>();
        } else if (key == "detp_index") s.estimator.detpIndex = parseDetpIndex(str(), path);
        else if (key == "detp_boundary") s.estimator.boundary = parseDetpBoundary(str(), path);
        else if (key == "photons") s.photons = checkedPhotons(jsonInteger(v, path, key), path, key);
        else if (key == "seed") s.seed = uint64_t(checkedInteger(jsonInteger(v, path, key), 0, kMaxSeed, path, key));
        else if (key == "max_bounces")
            s.maxBounces = uint32_t(checkedInteger(jsonInteger(v, path, key), 1, kMaxBounces, path, key,
                                                   " (the bounce field of a segment is 16 bits)"));
        else if (key == "sampler") s.sampling.kind = parseSampler(str(), path);
        else if (key == "qmc_bounces") {
            s.sampling.qmcBounces = checkedQmcBounces(jsonInteger(v, path, key), path, key);
            s.qmcBouncesGiven = true;
        }
        else if (key == "threads")
            s.threads = int(checkedInteger(jsonInteger(v, path, key), 0, kMaxThreads, path, key, " (0: all cores)"));
        else if (key == "frames") {
            s.frames = parseFrameRange(str(), path);
            s.framesSource = path;
        }
        else if (key == "lights") {
            if (!v.is_array()) throw InputError(path, key, "must be an array of lights");
            for (size_t i = 0; i < v.size(); ++i) s.extraLights.push_back(parseLight(v[i], path, "lights[" + std::to_string(i) + "]"));
        } else if (key == "width") s.width = int(checkedInteger(jsonInteger(v, path, key), 1, kMaxImageSide, path, key));
        else if (key == "height") s.height = int(checkedInteger(jsonInteger(v, path, key), 1, kMaxImageSide, path, key));
        else if (key == "spp")
            s.samplesPerPixel = int(checkedInteger(jsonInteger(v, path, key), 1, kMaxSamplesPerPixel, path, key));
        else if (key == "exr") {
            if (!v.is_boolean()) throw InputError(path, key, "must be true or false");
            s.writeExr = v.get<bool>();
        } else if (key == "exr_half") {
            if (!v.is_boolean()) throw InputError(path, key, "must be true or false");
            s.exrHalf = v.get<bool>();
        } else if (key == "png" || key == "gltf_out") {
            if (!v.is_boolean()) throw InputError(path, key, "must be true or false");
            (key == "png" ? s.writePng : s.writeGltf) = v.get<bool>();
        } else if (key == "exposure") {
            if (!v.is_number() || !(v.get<double>() > 0) || !std::isfinite(v.get<double>()))
                throw InputError(path, key, "must be a positive number");
            s.exposure = v.get<float>();
        } else if (key == "camera") {
            if (v.is_number()) {
                s.cameraIndex = int(checkedInteger(jsonInteger(v, path, key), 0, INT32_MAX, path, key));
                continue;
            }
            if (!v.is_object()) throw InputError(path, key, "must be a glTF camera index or {position, target, up, yfov}");
            refuseUnknownKeys(v, {"position", "target", "up", "yfov"}, path, key);
            if (!v.contains("position") || !v.contains("target"))
                throw InputError(path, key, "must be a glTF camera index or {position, target, up, yfov}");
            RenderSettings::LookAt c;
            c.position = vec3(v["position"], path, "camera.position");
            c.target = vec3(v["target"], path, "camera.target");
            if (v.contains("up")) c.up = vec3(v["up"], path, "camera.up");
            if (v.contains("yfov")) {
                if (!v["yfov"].is_number()) throw InputError(path, "camera.yfov", "must be a number (radians)");
                c.yfov = v["yfov"].get<float>();
            }
            s.camera = c;
        }
        // Any other key is a note for people ("_…", "comment"): refuseUnknownKeys let it through.
    }
}

}  // namespace

PhotonSampling effectiveSampling(const RenderSettings& s) {
    PhotonSampling sampling = s.sampling;
    sampling.qmcBounces = sampling.kind == SamplerKind::Random ? 0 : std::min({sampling.qmcBounces, s.maxBounces, kMaxQmcBounces});
    return sampling;
}

void validateSettings(const RenderSettings& s) {
    // Values from a config were checked against the config's name as they were read; these
    // checks catch the command line's (and any program that fills RenderSettings itself).
    const std::string cli = "command line";
    if (s.scenePath.empty()) throw InputError(cli, "SCENE", "no scene given");
    checkedPhotons(int64_t(std::min<uint64_t>(s.photons, INT64_MAX)), cli, "--photons");
    checkedInteger(s.maxBounces, 1, kMaxBounces, cli, "max_bounces", " (the bounce field of a segment is 16 bits)");
    // Checked here, after the config and the command line are merged: the bound is max_bounces.
    if (s.qmcBouncesGiven && s.sampling.kind == SamplerKind::Sobol)  // K means nothing under random
        checkedInteger(s.sampling.qmcBounces, 0, std::min<int64_t>(s.maxBounces, kMaxQmcBounces),
                       s.configPath.empty() ? cli : s.configPath + " or the command line", "qmc_bounces",
                       " (at most max_bounces, and the Sobol table covers 32 scatterings)");
    if (s.radiusGiven && !(s.estimator.radius > 0 && std::isfinite(s.estimator.radius)))
        throw InputError(cli, "--radius", "must be a positive number (scene units)");
    checkedInteger(s.estimator.k, 1, kMaxK, cli, "--k");
    checkedInteger(s.threads, 0, kMaxThreads, cli, "--threads", " (0: all cores)");
    if (s.width <= 0 || s.height <= 0 || s.width > kMaxImageSide || s.height > kMaxImageSide)
        throw InputError(cli, "--width/--height",
                         std::to_string(s.width) + "x" + std::to_string(s.height) + " is outside 1..16384 per side");
    checkedInteger(s.samplesPerPixel, 1, kMaxSamplesPerPixel, cli, "--spp");
    if (s.exposure && !(*s.exposure > 0 && std::isfinite(*s.exposure)))
        throw InputError(cli, "--exposure", "must be a positive number");
}

}  // namespace qsgi
