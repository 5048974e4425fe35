#include "pipeline/render_options.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "util/error.h"
#include "util/field_count.h"
#include "util/json_file.h"
#include "util/nearest_name.h"

namespace qsgi {

using nlohmann::json;

namespace {

// Relative paths in a config are relative to its folder; on the command line, to the working directory.
std::string resolved(const std::string& path, const OptionSource& source) {
    return source.base.empty() || std::filesystem::path(path).is_absolute() ? path : (source.base / path).string();
}

json orNull(bool meaningful, json value) { return meaningful ? std::move(value) : json(nullptr); }

template <class E, size_t N>
E choiceValue(const NamedValue<E> (&names)[N], const json& value) {
    return *valueNamed(names, value.get<std::string>());  // applyOption has checked the name
}

Vec3f vec3(const json& j, const std::string& file, const std::string& place) {
    if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
        throw InputError(file, place, "must be an array of 3 numbers");
    const double x = j[0].get<double>(), y = j[1].get<double>(), z = j[2].get<double>();
    const double largest = std::numeric_limits<float>::max();
    if (!(std::fabs(x) <= largest && std::fabs(y) <= largest && std::fabs(z) <= largest))
        throw InputError(file, place, "holds a number beyond single precision");
    return Vec3f(float(x), float(y), float(z));
}
json toJson(const Vec3f& v) { return json::array({v.x, v.y, v.z}); }

// A radiance: [r, g, b] or one number (grey) in a config, "R,G,B" or "V" on the command line;
// finite and non-negative.
Vec3f parseRadiance(const json& j, const std::string& file, const std::string& place) {
    json value = j;
    if (j.is_string()) {
        // "R,G,B" as the JSON array it spells; anything else is refused below.
        value = json::parse("[" + j.get<std::string>() + "]", nullptr, false);
        if (value.is_array() && value.size() == 1) value = value[0];
    }
    const char* shape = "must be a radiance (W m^-2 sr^-1): [r, g, b] or one number in a config, R,G,B or V on the command line";
    Vec3f radiance;
    if (value.is_number()) {
        const double v = value.get<double>();
        if (!(std::fabs(v) <= std::numeric_limits<float>::max())) throw InputError(file, place, "holds a number beyond single precision");
        radiance = Vec3f(float(v));
    } else if (value.is_array() && value.size() == 3) {
        radiance = vec3(value, file, place);
    } else {
        throw InputError(file, place, shape);
    }
    if (radiance.x < 0 || radiance.y < 0 || radiance.z < 0) throw InputError(file, place, "must be non-negative");
    return radiance;
}

// An equirectangular map: its path, or {"image", "intensity", "rotation"} (the "type" key
// allowed, as a "lights" entry has it).
void parseEnvironmentMap(const json& j, const OptionSource& src, EnvironmentSettings& e) {
    if (j.is_string()) {
        if (j.get<std::string>().empty()) throw InputError(src.file, src.place, "must name an image file");
        e = EnvironmentSettings{};
        e.image = resolved(j, src);
        e.source = src.file;
        return;
    }
    const char* shape = "must be an image's path or {\"image\": FILE, \"intensity\": k, \"rotation\": degrees}";
    if (!j.is_object()) throw InputError(src.file, src.place, shape);
    refuseUnknownKeys(j, {"type", "image", "intensity", "rotation"}, src.file, src.place);
    if (!j.contains("image") || !j["image"].is_string() || j["image"].get<std::string>().empty())
        throw InputError(src.file, src.place + ".image", "must name an image file (EXR, Radiance HDR, anything OpenImageIO reads)");
    EnvironmentSettings out;
    out.image = resolved(j["image"], src);
    out.source = src.file;
    if (j.contains("intensity")) {
        const json& k = j["intensity"];
        if (!k.is_number() || !(k.get<double>() > 0) || !(k.get<double>() <= double(std::numeric_limits<float>::max())))
            throw InputError(src.file, src.place + ".intensity", "must be a positive number (the map's pixels are multiplied by it)");
        out.intensity = k.get<float>();
    }
    if (j.contains("rotation")) {
        const json& r = j["rotation"];
        if (!r.is_number() || !(std::fabs(r.get<double>()) <= 1e6))
            throw InputError(src.file, src.place + ".rotation", "must be a number of degrees (about +Y, counter-clockwise seen from above)");
        out.rotationDegrees = r.get<float>();
    }
    e = out;
}

// A length option that is off at 0 (--subdivide, --refine-contacts): a float whose positive
// range the declaration checks, refused where float rounds it to 0; null in the log when off.
float positiveLength(const json& v, const OptionSource& src) {
    const float length = v.get<float>();
    if (!(length > 0)) throw InputError(src.file, src.place, "is below single precision's smallest length");
    return length;
}
json lengthOrOff(float length) { return length > 0 ? json(length) : json(nullptr); }

json environmentJson(const EnvironmentSettings& e) {
    if (e.image.empty()) return nullptr;
    return {{"image", pathJson(e.image)}, {"intensity", e.intensity}, {"rotation", e.rotationDegrees}};
}

// A light's direction made unit in double, scaled by its largest component first: a finite
// direction such as [0, -1e30, 0], whose squares overflow float, is a direction, not zero.
Vec3f unitDirection(const Vec3f& given, const std::string& file, const std::string& place) {
    const double largest = std::max({std::fabs(double(given.x)), std::fabs(double(given.y)), std::fabs(double(given.z))});
    if (!(largest > 0)) throw InputError(file, place, "must not be zero");
    const Vec3d scaled = Vec3d(given) / largest;
    return Vec3f(scaled / length(scaled));
}

PunctualLight parseLight(const json& j, const std::string& file, const std::string& place) {
    if (!j.is_object() || !j.contains("type") || !j["type"].is_string())
        throw InputError(file, place, "must be an object with a \"type\" (point, spot, directional, sky or environment)");
    refuseUnknownKeys(j, {"type", "position", "intensity", "direction", "irradiance", "name", "outer_cone_angle", "inner_cone_angle"},
                      file, place);
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
        l.direction = unitDirection(vec3(j["direction"], file, place + ".direction"), file, place + ".direction");
        l.intensity = nonNegative(vec3(j["irradiance"], file, place + ".irradiance"), "irradiance");
    } else if (type == "spot") {
        // As KHR_lights_punctual's: intensity in W/sr on the axis, cone angles in radians from it.
        l.type = LightType::Spot;
        if (!j.contains("position") || !j.contains("direction") || !j.contains("intensity"))
            throw InputError(file, place, "a spot light needs \"position\", \"direction\" and \"intensity\" (W/sr)");
        l.position = vec3(j["position"], file, place + ".position");
        l.direction = unitDirection(vec3(j["direction"], file, place + ".direction"), file, place + ".direction");
        l.intensity = nonNegative(vec3(j["intensity"], file, place + ".intensity"), "intensity");
        auto angle = [&](const char* key, double fallback) {
            if (!j.contains(key)) return fallback;
            if (!j[key].is_number()) throw InputError(file, place + "." + key, "must be a number (radians)");
            return j[key].get<double>();
        };
        const double outer = angle("outer_cone_angle", M_PI / 4), inner = angle("inner_cone_angle", 0);
        if (!(outer > 0 && outer <= M_PI / 2 + 1e-9))
            throw InputError(file, place + ".outer_cone_angle", "must lie in (0, pi/2] (as KHR_lights_punctual's)");
        if (!(inner >= 0 && inner < outer))
            throw InputError(file, place + ".inner_cone_angle", "must lie in [0, outer_cone_angle)");
        // The inner angle is checked as glTF's is, and not used: qsgi's spot lights, glTF's too,
        // send their intensity uniformly up to the outer cone (docs/inputs.md).
        l.cosOuterCone = float(std::cos(outer));
    } else {
        throw InputError(file, place + ".type",
                         "unknown light type '" + type + "' (point, spot, directional, sky or environment)");
    }
    return l;
}

json lightJson(const PunctualLight& l) {
    if (l.type == LightType::Spot)
        return {{"type", "spot"}, {"position", toJson(l.position)}, {"direction", toJson(l.direction)},
                {"intensity", toJson(l.intensity)}, {"outer_cone_angle", std::acos(double(l.cosOuterCone))}};
    if (l.type == LightType::Directional)
        return {{"type", "directional"}, {"direction", toJson(l.direction)}, {"irradiance", toJson(l.intensity)}};
    return {{"type", "point"}, {"position", toJson(l.position)}, {"intensity", toJson(l.intensity)}};
}

void setCamera(RenderSettings& s, const json& v, const OptionSource& src) {
    if (v.is_number()) {
        const int64_t index = v.is_number_integer() ? v.get<int64_t>() : -1;
        if (v.is_number_float() && std::floor(v.get<double>()) == v.get<double>() && std::fabs(v.get<double>()) < 1e10)
            return setCamera(s, json(int64_t(v.get<double>())), src);
        s.cameraIndex = int(checkedInteger(index, 0, INT32_MAX, src.file, src.place, " (a glTF camera index)"));
        s.camera.reset();
        return;
    }
    const char* shape = "must be a glTF camera index or {position, target, up, yfov}";
    if (!v.is_object()) throw InputError(src.file, src.place, shape);
    refuseUnknownKeys(v, {"position", "target", "up", "yfov"}, src.file, src.place);
    if (!v.contains("position") || !v.contains("target")) throw InputError(src.file, src.place, shape);
    RenderSettings::LookAt c;
    c.position = vec3(v["position"], src.file, src.place + ".position");
    c.target = vec3(v["target"], src.file, src.place + ".target");
    if (v.contains("up")) c.up = vec3(v["up"], src.file, src.place + ".up");
    if (v.contains("yfov")) {
        if (!v["yfov"].is_number() || !std::isfinite(v["yfov"].get<double>()))
            throw InputError(src.file, src.place + ".yfov", "must be a number (radians)");
        c.yfov = v["yfov"].get<float>();
    }
    s.camera = c;
    s.cameraIndex.reset();
}

json getCamera(const RenderSettings& s) {
    if (s.camera)
        return {{"position", toJson(s.camera->position)}, {"target", toJson(s.camera->target)},
                {"up", toJson(s.camera->up)}, {"yfov", s.camera->yfov}};
    return s.cameraIndex ? json(*s.cameraIndex) : json(nullptr);
}

// Every setting is reachable: each field of RenderSettings and of the stage settings it holds is
// set by an option below, except the eight that record where values came from (configPath,
// radiusGiven, qmcBouncesGiven, gatherGiven, directSamplesGiven, photonsGiven, framesSource,
// EnvironmentSettings' source), EmissionAim's margin (FrameSolver
// sets it from the estimator) and UpdateSettings' trackedGenerations (tests lower it). A field
// added without an option fails here; add its option (and count it).
static_assert(fieldCount<RenderSettings>() == 41, "a RenderSettings field was added or removed: give it an option below");
static_assert(fieldCount<TraceSettings>() == 5, "a TraceSettings field was added or removed: give it an option");
static_assert(fieldCount<EmissionAim>() == 2, "an EmissionAim field was added or removed: give it an option");
static_assert(fieldCount<PhotonSampling>() == 2, "a PhotonSampling field was added or removed: give it an option");
static_assert(fieldCount<EstimatorSettings>() == 6, "an EstimatorSettings field was added or removed: give it an option");
static_assert(fieldCount<PhotonMapSettings>() == 1, "a PhotonMapSettings field was added or removed: give it an option");
static_assert(fieldCount<DetpSettings>() == 2, "a DetpSettings field was added or removed: give it an option");
static_assert(fieldCount<LightingSettings>() == 4, "a LightingSettings field was added or removed: give it an option");
static_assert(fieldCount<EnvironmentSettings>() == 5, "an EnvironmentSettings field was added or removed: give it an option");
static_assert(fieldCount<UpdateSettings>() == 5, "an UpdateSettings field was added or removed: give it an option");

std::vector<RenderOption> declareOptions() {
    using T = OptionType;
    std::vector<RenderOption> o;
    // Inputs
    o.push_back({"scene", "SCENE", T::Text, 0, 0, "", {}, true, "", "from --config",
                 "glTF 2.0 scene, .gltf (external or embedded buffers) or .glb", true, false,
                 [](RenderSettings& s, const json& v, const OptionSource& src) { s.scenePath = resolved(v, src); },
                 [](const RenderSettings& s) { return s.scenePath.empty() ? json(nullptr) : json(s.scenePath); }});
    o.push_back({"animation", "--animation", T::Text, 0, 0, "", {}, true, "FILE|gltf|gltf:N", "none: one frame, 0",
                 "a qsgi-animation transform file (docs/inputs.md); gltf plays every animation in the scene file at "
                 "once, gltf:N its animation N (the file's content, not its path, enters the fingerprint)",
                 false, false,
                 [](RenderSettings& s, const json& v, const OptionSource& src) {
                     const std::string a = v;
                     s.animationPath = gltfAnimationSelector(a, src.file) ? a : resolved(a, src);
                 },
                 [](const RenderSettings& s) { return s.animationPath.empty() ? json(nullptr) : json(s.animationPath); }});
    o.push_back({"strict", "--strict", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "refuse (exit 2) glTF errors in objects the render does not use, which are otherwise warnings; for "
                 "pipelines that gate exporters",
                 false, true, [](RenderSettings& s, const json& v, const OptionSource&) { s.strict = v; },
                 [](const RenderSettings& s) { return json(s.strict); }});
    o.push_back({"fps", "--fps", T::Number, 0, 1e6, "", {}, true, "F", "24",
                 "frames per second at which a glTF animation is sampled (glTF has no frame rate)", true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.fps = v.get<double>(); },
                 [](const RenderSettings& s) { return json(s.fps.value_or(kDefaultGltfFps)); }});
    o.push_back({nullptr, "--config", T::Text, 0, 0, "", {}, true, "FILE", "",
                 "a JSON config with these keys (configs/default.json); options on the command line override it", false,
                 false, nullptr, nullptr});
    // Estimation
    o.push_back({"estimator", "--estimator", T::Choice, 0, 0, "", namesOf(kEstimatorNames), true, "", "impact-count",
                 "the density estimator: impact-count (the paper's impact count), photon-map or detp (density estimation on the tangent plane; docs/method.md)", true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.estimator.kind = choiceValue(kEstimatorNames, v); },
                 [](const RenderSettings& s) { return json(estimatorName(s.estimator.kind)); }});
    o.push_back({"radius", "--radius", T::Number, 0, 1e30, " (scene units)", {}, true, "R",
                 "1.5 % of the animation's bounding-box diagonal",
                 "DETP disc radius and photon-map search radius, scene units", true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) {
                     s.estimator.radius = v.get<float>();
                     s.radiusGiven = true;
                 },
                 [](const RenderSettings& s) {
                     return orNull(s.estimator.kind != EstimatorKind::ImpactCount, json(s.estimator.radius));
                 }});
    o.push_back({"k", "--k", T::Integer, 1, double(kMaxK), "", {}, true, "K", "50",
                 "photon map: the nearest impacts per vertex", true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.estimator.photonMap.k = v.get<int>(); },
                 [](const RenderSettings& s) { return orNull(s.estimator.kind == EstimatorKind::PhotonMap, json(s.estimator.photonMap.k)); }});
    o.push_back({"detp_boundary", "--detp-boundary", T::Choice, 0, 0, "", namesOf(kDetpBoundaryNames), true, "", "clip",
                 "where a disc meets other geometry: clip (only the parts of the disc light can reach from the vertex's "
                 "side count: no leaks through thin occluders), linear (clip plus a linear fit that removes the "
                 "first-order bias at edges) or paper (the published rule, and the textbook photon map: for ablations)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) {
                     s.estimator.detp.boundary = choiceValue(kDetpBoundaryNames, v);
                 },
                 [](const RenderSettings& s) {
                     return orNull(s.estimator.kind != EstimatorKind::ImpactCount, json(detpBoundaryName(s.estimator.detp.boundary)));
                 }});
    o.push_back({"detp_index", "--detp-index", T::Choice, 0, 0, "", namesOf(kDetpIndexNames), true, "", "embree",
                 "DETP's index: embree (exact) or flann (approximate candidates: it misses segments that cross a disc "
                 "but land far away)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.estimator.detp.index = choiceValue(kDetpIndexNames, v); },
                 [](const RenderSettings& s) {
                     return orNull(s.estimator.kind == EstimatorKind::Detp, json(nameOf(kDetpIndexNames, s.estimator.detp.index)));
                 }});
    o.push_back({"ray_cache", "--no-ray-cache", T::Boolean, 0, 0, "", {}, false, "", "true",
                 "no spatial index, every vertex against every segment or impact (the paper's \"No Ray Caché\"; "
                 "slow, the reference)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.estimator.useIndex = v; },
                 [](const RenderSettings& s) { return json(s.estimator.useIndex); }});
    o.push_back({"sort_queries", "--no-sort-queries", T::Boolean, 0, 0, "", {}, false, "", "true",
                 "queries in input order instead of Morton order", true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.estimator.sortQueries = v; },
                 [](const RenderSettings& s) { return json(s.estimator.sortQueries); }});
    // The second pass (docs/design.md §5.1)
    o.push_back({"direct", "--direct", T::Choice, 0, 0, "", namesOf(kDirectLightingNames), true, "", "exact",
                 "direct light: exact (shadow rays from each vertex; the estimator then counts only light after its "
                 "first bounce) or photons (all of it from the photons: the paper's method)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) {
                     s.lighting.direct = choiceValue(kDirectLightingNames, v);
                 },
                 [](const RenderSettings& s) { return json(directLightingName(s.lighting.direct)); }});
    o.push_back({"direct_samples", "--direct-samples", T::Integer, 1, double(kMaxDirectSamples), "", {}, true, "S", "64",
                 "exact direct only: shadow rays per vertex toward the emissive triangles, chosen through a light "
                 "tree (one per point, spot and directional light besides while there are at most S; past S they "
                 "are sampled too)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) {
                     s.lighting.directSamples = v.get<uint32_t>();
                     s.directSamplesGiven = true;
                 },
                 [](const RenderSettings& s) { return orNull(s.lighting.exactDirect(), json(s.lighting.directSamples)); }});
    o.push_back({"gather", "--gather", T::Integer, 0, double(kMaxGatherRays), "", {}, true, "M", "256",
                 "exact direct only: final-gather rays per vertex over the photon solution (0: none; the vertex then "
                 "takes the estimator's indirect light as it is)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) {
                     s.lighting.gatherRays = v.get<uint32_t>();
                     s.gatherGiven = true;
                 },
                 [](const RenderSettings& s) { return orNull(s.lighting.exactDirect(), json(s.lighting.gatherRays)); }});
    o.push_back({"gather_cache", "--gather-cache", T::Object, 0, 0, "", {}, true, "auto|off|A", "auto",
                 "with a gather: full gathers only at records spaced A times the distance to the geometry around "
                 "them (crowding at contacts and edges), every other vertex interpolated from the records it "
                 "reaches across its own surface (docs/method.md, the gather cache); A a number in [0, 1], 0 "
                 "every vertex a record (the per-vertex gather's bytes); off: every vertex gathers; auto: A = 0.2 "
                 "on scenes of 10^4 vertices or more, else off",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource& src) {
                     const std::string word = v.is_string() ? v.get<std::string>() : "";
                     if (word == "off" || word == "auto") {
                         s.lighting.gatherCache = word == "off" ? LightingSettings::kGatherCacheOff : LightingSettings::kGatherCacheAuto;
                         return;
                     }
                     if (!v.is_number() || !(v.get<double>() >= 0 && v.get<double>() <= 1))
                         throw InputError(src.file, src.place, "must be auto, off or a number in [0, 1] (the cache's tolerance)");
                     s.lighting.gatherCache = v.get<float>();
                 },
                 [](const RenderSettings& s) {
                     if (!s.lighting.gathers()) return json(nullptr);
                     if (s.lighting.gatherCache == LightingSettings::kGatherCacheAuto) return json("auto");
                     return s.lighting.gatherCache >= 0 ? json(s.lighting.gatherCache) : json("off");
                 }});
    // Frames after the first
    o.push_back({"full_recompute", "--full-recompute", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "compute every frame from scratch instead of updating the previous one (the same bytes; the "
                 "baseline of the update's speed)",
                 false, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.update.fullRecompute = v; },
                 [](const RenderSettings& s) { return json(s.update.fullRecompute); }});
    o.push_back({"always_update", "--always-update", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "update every frame after the first, even one whose change would cost more to update than to "
                 "recompute (the same bytes; for measuring the update)",
                 false, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.update.alwaysUpdate = v; },
                 [](const RenderSettings& s) { return json(s.update.alwaysUpdate); }});
    o.push_back({"envelope", "--no-envelope", T::Boolean, 0, 0, "", {}, false, "", "true",
                 "track every light path instead of only those meeting the moving geometry's envelope (the same "
                 "bytes; more memory and work per frame)",
                 false, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.update.useEnvelope = v; },
                 [](const RenderSettings& s) { return json(s.update.useEnvelope); }});
    o.push_back({"blocking_grid", nullptr, T::Boolean, 0, 0, "", {}, true, "", "true",
                 "test every tracked segment against the moved geometry instead of those the grid finds (the "
                 "same bytes; for measuring the grid)",
                 false, false,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.update.gridForBlocking = v; },
                 [](const RenderSettings& s) { return json(s.update.gridForBlocking); }});
    // Photons
    o.push_back({"aim_emission", "--no-aim", T::Boolean, 0, 0, "", {}, false, "", "true",
                 "point, spot and directional lights emit in every direction instead of only toward what photons can "
                 "reach (projection maps; docs/command-line.md)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.trace.aim.enabled = v; },
                 [](const RenderSettings& s) { return json(s.trace.aim.enabled); }});
    o.push_back({"photons", "--photons", T::Integer, 1, double(kMaxPhotons), " (2^32: the path index is 32 bits)", {},
                 true, "N", "1000000", "photons traced per frame", true, true,
                 [](RenderSettings& s, const json& v, const OptionSource& src) {
                     s.trace.photons = checkedPhotons(v.get<int64_t>(), src.file, src.place);
                     s.photonsGiven = true;
                 },
                 [](const RenderSettings& s) { return json(s.trace.photons); }});
    {
        std::vector<std::string> levels;
        for (const QualityLevel& level : kQualityLevels) levels.push_back(level.name);
        // Not fingerprinted itself: the values it sets are, so a level and the same options given
        // one by one make the same run.
        o.push_back({"quality", "--quality", T::Choice, 0, 0, "", levels, true, "LEVEL", kDefaultQuality,
                     "speed against accuracy in one knob: sets photons, gather and direct_samples, each where "
                     "not given itself (draft 100k photons, gather 64, 16 shadow rays; fast 300k, 256, 64; "
                     "standard, the defaults, 10^6, 256, 64; high 10^6, 1024, 64; measured error and time: "
                     "docs/photons-and-radius.md)",
                     false, true,
                     [](RenderSettings& s, const json& v, const OptionSource&) {
                         s.quality = v.get<std::string>();
                         const QualityLevel& level = qualityLevel(s.quality);
                         if (!s.photonsGiven) s.trace.photons = level.photons;
                         if (!s.gatherGiven) s.lighting.gatherRays = level.gatherRays;
                         if (!s.directSamplesGiven) s.lighting.directSamples = level.directSamples;
                     },
                     [](const RenderSettings& s) { return json(s.quality); }});
    }
    o.push_back({"seed", "--seed", T::Integer, 0, double(kMaxSeed), "", {}, true, "S", "1",
                 "the random seed: the same inputs and seed give the same bytes for any thread count", true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.trace.seed = v.get<uint64_t>(); },
                 [](const RenderSettings& s) { return json(s.trace.seed); }});
    o.push_back({"max_bounces", "--max-bounces", T::Integer, 1, double(kMaxBounces),
                 " (the bounce field of a segment is 16 bits)", {}, true, "B", "32",
                 "the most scatterings a photon's path may have (Russian roulette ends most paths long before)", true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.trace.maxBounces = v.get<uint32_t>(); },
                 [](const RenderSettings& s) { return json(s.trace.maxBounces); }});
    o.push_back({"sampler", "--sampler", T::Choice, 0, 0, "", namesOf(kSamplerNames), true, "", "sobol",
                 "where each photon's numbers come from: sobol (an Owen-scrambled Sobol point per photon, each light its "
                 "own sequence; docs/photons-and-radius.md) or random (hashed, independent: the paper's kind)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.trace.sampling.kind = choiceValue(kSamplerNames, v); },
                 [](const RenderSettings& s) { return json(samplerName(s.trace.sampling.kind)); }});
    o.push_back({"qmc_bounces", "--qmc-bounces", T::Integer, 0, double(kMaxQmcBounces),
                 " (the Sobol table covers that many scatterings)", {}, true, "K", "2",
                 "sobol only: the first K scatterings take their survival and direction from the Sobol point too (at "
                 "most max_bounces); later ones are hashed",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) {
                     s.trace.sampling.qmcBounces = v.get<uint32_t>();
                     s.qmcBouncesGiven = true;
                 },
                 // The K that shapes the bytes: none under random, capped at max_bounces.
                 [](const RenderSettings& s) {
                     return orNull(s.trace.sampling.kind == SamplerKind::Sobol, json(effectiveTrace(s.trace).sampling.qmcBounces));
                 }});
    // Running
    o.push_back({"threads", "--threads", T::Integer, 0, double(kMaxThreads), " (0: all cores)", {}, true, "T", "0",
                 "worker threads, 0 = all cores (any count gives the same bytes)", false, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.threads = v.get<int>(); },
                 [](const RenderSettings& s) { return json(s.threads); }});
    o.push_back({"frames", "--frames", T::Text, 0, 0, "", {}, true, "A:B", "all",
                 "frames A to B, inclusive at both ends (0:0 is frame 0 alone)", false, false,
                 [](RenderSettings& s, const json& v, const OptionSource& src) {
                     s.frames = parseFrameRange(v, src.file);
                     s.framesSource = src.file;
                 },
                 [](const RenderSettings& s) {
                     return s.frames ? json(std::to_string(s.frames->first) + ":" + std::to_string(s.frames->last)) : json(nullptr);
                 }});
    o.push_back({"out", "--out", T::Text, 0, 0, "", {}, true, "DIR", "out",
                 "the output folder, created (relative to the working directory, also in a config)", false, false,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.outDir = v; },
                 [](const RenderSettings& s) { return json(s.outDir); }});
    o.push_back({nullptr, "--resume", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "continue the output folder after its last complete frame (the same inputs and fingerprinted settings "
                 "only)",
                 false, false, [](RenderSettings& s, const json& v, const OptionSource&) { s.resume = v; },
                 [](const RenderSettings& s) { return json(s.resume); }});
    o.push_back({nullptr, "--overwrite", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "when the output folder holds another run (other inputs or settings), unlink its frame_NNNN.{ply,exr,png,glb} files "
                 "and timing.json first (nothing else, never recursively); without it such a folder is refused",
                 false, false, [](RenderSettings& s, const json& v, const OptionSource&) { s.overwrite = v; },
                 [](const RenderSettings& s) { return json(s.overwrite); }});
    // Lights added to the scene
    o.push_back({"lights", nullptr, T::Object, 0, 0, "", {}, true, "", "none",
                 "lights added to any scene, world space: [{\"type\": \"point\", \"position\": [x,y,z], \"intensity\": "
                 "[r,g,b] (W/sr)}, {\"type\": \"spot\", \"position\", \"direction\", \"intensity\", \"outer_cone_angle\", "
                 "\"inner_cone_angle\" (radians, as KHR_lights_punctual)}, {\"type\": \"directional\", \"direction\": [x,y,z], "
                 "\"irradiance\": [r,g,b] (W/m^2)}, {\"type\": \"sky\", \"radiance\": [r,g,b]} or {\"type\": \"environment\", "
                 "\"image\": FILE, \"intensity\": k, \"rotation\": degrees} (at most one of the last two; as sky and environment)]",
                 true, false,
                 [](RenderSettings& s, const json& v, const OptionSource& src) {
                     if (!v.is_array()) throw InputError(src.file, src.place, "must be an array of lights");
                     std::string environmentAt;  // the entry that gave the environment, if one did
                     for (size_t i = 0; i < v.size(); ++i) {
                         const std::string place = src.place + "[" + std::to_string(i) + "]";
                         const json& entry = v[i];
                         const std::string type = entry.is_object() && entry.contains("type") && entry["type"].is_string()
                                                      ? entry["type"].get<std::string>() : "";
                         if (type != "sky" && type != "environment") {
                             s.extraLights.push_back(parseLight(entry, src.file, place));
                             continue;
                         }
                         if (!environmentAt.empty())
                             throw InputError(src.file, place, "a second sky or environment (the first is " + environmentAt +
                                                                   "): a scene has at most one");
                         environmentAt = place;
                         if (type == "environment") {
                             parseEnvironmentMap(entry, OptionSource{src.file, place, src.base}, s.environment);
                             continue;
                         }
                         refuseUnknownKeys(entry, {"type", "radiance"}, src.file, place);
                         if (!entry.contains("radiance")) throw InputError(src.file, place, "a sky needs \"radiance\": [r, g, b]");
                         s.environment = EnvironmentSettings{};
                         s.environment.sky = parseRadiance(entry["radiance"], src.file, place + ".radiance");
                         s.environment.source = src.file;
                     }
                 },
                 [](const RenderSettings& s) {
                     if (s.extraLights.empty()) return json(nullptr);
                     json list = json::array();
                     for (const PunctualLight& l : s.extraLights) list.push_back(lightJson(l));
                     return list;
                 }});
    o.push_back({"sky", "--sky", T::Object, 0, 0, "", {}, true, "R,G,B", "none",
                 "a uniform sky of this radiance (W m^-2 sr^-1; one number is grey) lights the scene from every "
                 "direction, replacing an environment map",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource& src) {
                     s.environment = EnvironmentSettings{};
                     s.environment.sky = parseRadiance(v, src.file, src.place);
                     s.environment.source = src.file;
                 },
                 [](const RenderSettings& s) { return s.environment.sky ? toJson(*s.environment.sky) : json(nullptr); }});
    o.push_back({"environment", "--environment", T::Object, 0, 0, "", {}, true, "FILE", "none",
                 "an equirectangular HDR map (EXR, Radiance HDR) lights the scene from every direction, replacing a "
                 "sky; in a config also {\"image\": FILE, \"intensity\": k, \"rotation\": degrees about +Y} "
                 "(docs/inputs.md: the map's orientation)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource& src) { parseEnvironmentMap(v, src, s.environment); },
                 [](const RenderSettings& s) { return environmentJson(s.environment); }});
    o.push_back({"subdivide", "--subdivide", T::Number, 0, kMaxSceneExtent, "", {}, true, "LENGTH", "off",
                 "refine every triangle with an edge longer than LENGTH (scene units) before the bake, once on the "
                 "rest pose, without T-junctions; every output holds the refined mesh (docs/inputs.md: coarse meshes)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource& src) { s.subdivide = positiveLength(v, src); },
                 [](const RenderSettings& s) { return lengthOrOff(s.subdivide); }});
    o.push_back({"refine_contacts", "--refine-contacts", T::Number, 0, kMaxSceneExtent, "", {}, true, "DISTANCE", "off",
                 "refine, until at most DISTANCE/2 long, every edge that passes within DISTANCE of another piece of "
                 "surface in any frame (a block's foot, feet on a floor, the ceiling round a fixture), once on the rest "
                 "pose, after --subdivide and without T-junctions; every output holds the refined mesh (docs/method.md: "
                 "contacts)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource& src) { s.refineContacts = positiveLength(v, src); },
                 [](const RenderSettings& s) { return lengthOrOff(s.refineContacts); }});
    o.push_back({"vertex_fit", "--vertex-fit", T::Choice, 0, 0, "", namesOf(kVertexFitNames), true, "", "point",
                 "each vertex's value: point (its own irradiance) or least-squares (the values whose interpolation "
                 "across the triangles is closest to the irradiance sampled over them; the samples are the vertices of "
                 "the mesh refined near contacts as --refine-contacts R would, R 1.5 % of the animation's diagonal, "
                 "hidden and covered ones (inside or under closed geometry) left out; the output keeps its vertices; "
                 "docs/method.md: the least-squares vertex fit)",
                 true, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.vertexFit = choiceValue(kVertexFitNames, v); },
                 [](const RenderSettings& s) { return json(nameOf(kVertexFitNames, s.vertexFit)); }});
    // Images
    o.push_back({"width", "--width", T::Integer, 1, double(kMaxImageSide), "", {}, true, "W", "640",
                 "image width in pixels", true, false,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.width = v.get<int>(); },
                 [](const RenderSettings& s) { return json(s.width); }});
    o.push_back({"height", "--height", T::Integer, 1, double(kMaxImageSide), "", {}, true, "H", "480",
                 "image height in pixels", true, false,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.height = v.get<int>(); },
                 [](const RenderSettings& s) { return json(s.height); }});
    o.push_back({"spp", "--spp", T::Integer, 1, double(kMaxSamplesPerPixel), "", {}, true, "N", "1",
                 "primary rays per pixel (1: the pixel centre; more: jittered, the same every run)", true, false,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.samplesPerPixel = v.get<int>(); },
                 [](const RenderSettings& s) { return json(s.samplesPerPixel); }});
    o.push_back({"camera", "--camera", T::Object, 0, 0, "", {}, true, "I", "the first camera node",
                 "a glTF camera index; in a config also {\"position\": [x,y,z], \"target\": [x,y,z], \"up\": [0,1,0], "
                 "\"yfov\": 0.8} in world space, radians",
                 true, false, setCamera, getCamera});
    o.push_back({"exr", "--no-exr", T::Boolean, 0, 0, "", {}, false, "", "true", "write no frame_NNNN.exr", true,
                 false, [](RenderSettings& s, const json& v, const OptionSource&) { s.writeExr = v; },
                 [](const RenderSettings& s) { return json(s.writeExr); }});
    o.push_back({"exr_half", "--exr-half", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "EXR pixels as half floats instead of float", true, false,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.exrHalf = v; },
                 [](const RenderSettings& s) { return json(s.exrHalf); }});
    o.push_back({"png", "--png", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "also write an 8-bit sRGB preview frame_NNNN.png (on in configs/default.json)", true, false,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.writePng = v; },
                 [](const RenderSettings& s) { return json(s.writePng); }});
    o.push_back({"gltf_out", "--gltf-out", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "also write asset.glb: the scene's own glTF file, every object kept, with the bake on each rendered "
                 "primitive as _RADIANCE (B/pi) and _IRRADIANCE (E, before the albedo); an animation's frames as "
                 "morph targets a STEP weights animation plays (docs/outputs.md)",
                 false, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.writeGltf = v; },
                 [](const RenderSettings& s) { return json(s.writeGltf); }});
    o.push_back({"gltf_colour", "--gltf-colour", T::Integer, 0, 255, "", {}, true, "N", "none",
                 "with --gltf-out, also add the vertex colour set COLOR_N = min(1, exposure * B/pi) (the first frame's "
                 "99th percentile at 1); N must be the primitives' next free set: an existing one is never overwritten",
                 false, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.gltfColourSet = v.get<int>(); },
                 [](const RenderSettings& s) { return s.gltfColourSet >= 0 ? json(s.gltfColourSet) : json(nullptr); }});
    o.push_back({"usd_out", "--usd-out", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "also write asset.usda: the scene's meshes with the bake as colours sampled at every frame "
                 "(primvars radiance = B/pi and irradiance = E) and materials that show it by emission; Blender plays "
                 "it on import (docs/outputs.md)",
                 false, true,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.writeUsd = v; },
                 [](const RenderSettings& s) { return json(s.writeUsd); }});
    o.push_back({nullptr, "--frames-only", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "write each frame's files and timing.json only, never asset.glb or asset.usda whatever --gltf-out and "
                 "--usd-out say: what each "
                 "chunk of a Slurm array runs (the finishing run makes the asset once, from every frame)",
                 false, false, [](RenderSettings& s, const json& v, const OptionSource&) { s.framesOnly = v; },
                 [](const RenderSettings& s) { return json(s.framesOnly); }});
    o.push_back({"exposure", "--exposure", T::Number, 0, 1e30, "", {}, true, "X",
                 "automatic: the 99th-percentile luminance of the first frame becomes 0.8",
                 "the PNG preview's exposure multiplier", true, false,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.exposure = v.get<float>(); },
                 [](const RenderSettings& s) { return s.exposure ? json(*s.exposure) : json(nullptr); }});
    // Messages
    o.push_back({nullptr, "--quiet", T::Boolean, 0, 0, "", {}, true, "", "false",
                 "print nothing but errors (no progress line, no summary, no warnings)", false, false,
                 [](RenderSettings& s, const json& v, const OptionSource&) { s.quiet = v; },
                 [](const RenderSettings& s) { return json(s.quiet); }});
    o.push_back({nullptr, "--verbose", T::Boolean, 0, 0, "", {}, true, "", "false", "print each frame's time", false,
                 false, [](RenderSettings& s, const json& v, const OptionSource&) { s.verbose = v; },
                 [](const RenderSettings& s) { return json(s.verbose); }});
    return o;
}

std::string numberText(double value) {
    char text[40];
    if (std::fabs(value) < 1e15 && std::floor(value) == value) std::snprintf(text, sizeof text, "%.0f", value);
    else std::snprintf(text, sizeof text, "%g", value);
    return text;
}

// An integer in [lo, hi], also when written as 1e6 (a float with no fraction); never wrapped.
int64_t checkedOptionInteger(const RenderOption& o, const json& v, const OptionSource& src) {
    const int64_t lo = int64_t(o.min), hi = o.max >= 9.2e18 ? INT64_MAX : int64_t(o.max);
    const std::string range = " is outside " + numberText(o.min) + ".." + (hi == INT64_MAX ? std::to_string(hi) : numberText(o.max)) + o.rangeNote;
    if (v.is_number_unsigned()) {
        const uint64_t u = v.get<uint64_t>();
        if (u > uint64_t(hi)) throw InputError(src.file, src.place, std::to_string(u) + range);
        return checkedInteger(int64_t(u), lo, hi, src.file, src.place, o.rangeNote);
    }
    if (v.is_number_integer()) return checkedInteger(v.get<int64_t>(), lo, hi, src.file, src.place, o.rangeNote);
    if (v.is_number_float()) {
        const double d = v.get<double>();
        if (std::isfinite(d) && std::floor(d) == d) {
            if (d < o.min || d > o.max) throw InputError(src.file, src.place, numberText(d) + range);
            return checkedInteger(int64_t(d), lo, hi, src.file, src.place, o.rangeNote);
        }
    }
    throw InputError(src.file, src.place, "must be an integer");
}

}  // namespace

const std::vector<RenderOption>& renderOptions() {
    static const std::vector<RenderOption> options = declareOptions();
    return options;
}

const RenderOption* optionWithKey(const std::string& key) {
    for (const RenderOption& o : renderOptions())
        if (o.key && key == o.key) return &o;
    return nullptr;
}

void applyOption(const RenderOption& o, const json& v, const OptionSource& src, RenderSettings& s) {
    switch (o.type) {
        case OptionType::Integer: o.set(s, json(checkedOptionInteger(o, v, src)), src); return;
        case OptionType::Number: {
            const std::string wanted = "must be a positive number, at most " + numberText(o.max) + o.rangeNote;
            if (!v.is_number()) throw InputError(src.file, src.place, wanted);
            const double d = v.get<double>();
            if (!(d > o.min && d <= o.max))
                throw InputError(src.file, src.place,
                                 numberText(d) + " is not a positive number at most " + numberText(o.max) + o.rangeNote);
            o.set(s, json(d), src);
            return;
        }
        case OptionType::Boolean:
            if (!v.is_boolean()) throw InputError(src.file, src.place, "must be true or false");
            o.set(s, v, src);
            return;
        case OptionType::Choice: {
            const std::string name = v.is_string() ? v.get<std::string>() : v.dump();
            std::string list;
            for (const std::string& c : o.choices) list += (list.empty() ? "" : ", ") + c;
            if (!v.is_string() || std::find(o.choices.begin(), o.choices.end(), name) == o.choices.end())
                throw InputError(src.file, src.place, "unknown " + std::string(o.key) + " '" + name + "'" +
                                                          didYouMean(name, o.choices) + " (available: " + list + ")");
            o.set(s, v, src);
            return;
        }
        case OptionType::Text:
            if (!v.is_string()) throw InputError(src.file, src.place, "must be a string");
            o.set(s, v, src);
            return;
        case OptionType::Object: o.set(s, v, src); return;
    }
}

void applyCommandLineOption(const RenderOption& o, const std::string& text, RenderSettings& s) {
    const OptionSource src{"command line", o.flag, {}};
    json value = text;
    if (o.type == OptionType::Integer || o.type == OptionType::Number || o.type == OptionType::Object) {
        // A number as JSON writes it ("1e6" too), or for a structured option a JSON object or array
        // as a config holds it; anything else is refused by the same check as a config's.
        value = json::parse(text, nullptr, false);
        const bool structured = o.type == OptionType::Object && (value.is_object() || value.is_array());
        if (value.is_discarded() || !(value.is_number() || structured)) value = text;
    }
    if (o.type == OptionType::Boolean) value = o.flagSets;
    applyOption(o, value, src, s);
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

json optionValues(const RenderSettings& s, OptionSelection selection) {
    json values = json::object();
    for (const RenderOption& o : renderOptions()) {
        if (!o.key || !o.get) continue;
        if (selection == OptionSelection::Fingerprinted && !o.fingerprinted) continue;
        if (selection == OptionSelection::Logged && !o.logged) continue;
        const json value = o.get(s);
        // Recorded (timing.json, the fingerprint): a path that is not UTF-8 as pathJson records it.
        values[o.key] = value.is_string() && selection != OptionSelection::All ? pathJson(value.get<std::string>()) : value;
    }
    return values;
}

json optionsDescription() {
    static const char* typeNames[] = {"integer", "number", "boolean", "choice", "text", "object"};
    json list = json::array();
    for (const RenderOption& o : renderOptions()) {
        json entry = {{"key", o.key ? json(o.key) : json(nullptr)}, {"flag", o.flag ? json(o.flag) : json(nullptr)},
                      {"type", typeNames[int(o.type)]}, {"default", o.defaultText}, {"help", o.help},
                      {"fingerprint", o.fingerprinted}, {"timing_log", o.logged}};
        if (o.type == OptionType::Integer || o.type == OptionType::Number) entry["range"] = {o.min, o.max};
        if (o.type == OptionType::Choice) entry["choices"] = o.choices;
        if (o.type == OptionType::Boolean && o.flag) entry["flag_sets"] = o.flagSets;
        list.push_back(entry);
    }
    return list;
}

std::string optionsMarkdownTable() {
    auto escaped = [](std::string text) {
        for (size_t i = 0; (i = text.find('|', i)) != std::string::npos; i += 2) text.replace(i, 1, "\\|");
        return text;
    };
    std::string table = "| command line | config key | meaning | default | fingerprint | timing.json |\n"
                        "|---|---|---|---|---|---|\n";
    for (const RenderOption& o : renderOptions()) {
        std::string flag = o.flag ? std::string(o.flag) : "";
        if (o.flag && *o.metavar) flag += " " + std::string(o.metavar);
        if (o.type == OptionType::Choice && o.flag) {
            std::string list;
            for (const std::string& c : o.choices) list += (list.empty() ? "" : "|") + c;
            flag += " " + list;
        }
        std::string meaning = o.help;
        if (o.type == OptionType::Boolean && o.key && o.flag && !o.flagSets)
            meaning = "false (the flag): " + meaning;
        else if (o.type == OptionType::Boolean && o.key && !o.flag)
            meaning = "false: " + meaning;
        if (o.type == OptionType::Integer && o.max > o.min)
            meaning += " (" + numberText(o.min) + "…" + (o.max >= 9.2e18 ? std::string("2^63-1") : numberText(o.max)) + ")";
        table += "| " + (flag.empty() ? "—" : "`" + escaped(flag) + "`") + " | " +
                 (o.key ? "`" + std::string(o.key) + "`" : "—") + " | " + escaped(meaning) + " | " +
                 (*o.defaultText ? escaped(o.defaultText) : "—") + " | " + (o.fingerprinted ? "yes" : "") + " | " +
                 (o.logged ? "yes" : "") + " |\n";
    }
    return table;
}

}  // namespace qsgi
