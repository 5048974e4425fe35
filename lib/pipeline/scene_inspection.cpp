#include "pipeline/scene_inspection.h"

#include <algorithm>
#include <cstdio>
#include <set>

#include "trace/light_sampler.h"

namespace qsgi {

namespace {

nlohmann::json vec(const Vec3f& v) { return {v.x, v.y, v.z}; }

const char* lightTypeName(LightType t) {
    switch (t) {
        case LightType::Point: return "point";
        case LightType::Spot: return "spot";
        case LightType::Directional: return "directional";
    }
    return "?";
}

std::string number(double x, const char* format = "%.4g") {
    char text[64];
    std::snprintf(text, sizeof text, format, x);
    return text;
}

}  // namespace

nlohmann::json inspectRender(const RenderJob& job, const Warnings& warnings) {
    const Scene& scene = job.scene();
    const RenderSettings& settings = job.settings();
    const Animation& animation = job.animation();
    nlohmann::json r;

    const Bounds3f bounds = scene.bounds();
    r["scene"] = {{"file", settings.scenePath},
                  {"mesh_instances", scene.instances.size()},
                  {"nodes", scene.nodes.size()},
                  {"triangles", scene.triangleCount()},
                  {"vertices", scene.vertexCount()},
                  {"bounds", {{"min", vec(bounds.lower)}, {"max", vec(bounds.upper)}}},
                  {"diagonal", bounds.extent()}};

    // Materials as the render uses them: albedo range and emitters, over triangles that have area.
    std::set<uint32_t> used, emissive;
    uint64_t emissiveTriangles = 0;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const uint32_t m = scene.triangleMaterial[t];
        used.insert(m);
        if (scene.materials[m].isEmissive() && scene.triangleArea(t) > 0) {
            emissive.insert(m);
            ++emissiveTriangles;
        }
    }
    Vec3f lowest(1e30f), highest(-1e30f);
    for (uint32_t m : used)
        for (int c = 0; c < 3; ++c) {
            lowest[c] = std::min(lowest[c], scene.materials[m].albedo[c]);
            highest[c] = std::max(highest[c], scene.materials[m].albedo[c]);
        }
    if (used.empty()) lowest = highest = Vec3f(0.0f);
    r["materials"] = {{"count", scene.materials.size()},
                      {"used", used.size()},
                      {"albedo_min", vec(lowest)},
                      {"albedo_max", vec(highest)},
                      {"emissive", emissive.size()},
                      {"emissive_triangles", emissiveTriangles}};

    // Each emitter's power as the photon tracer shares photons among them (unaimed).
    const LightSampler sampler(scene, 1, scene.sceneEpsilon());
    const std::vector<Vec3f> powers = sampler.lightPowers(scene.lights.size());
    const Vec3f trianglePower = sampler.emissiveTrianglePower();
    double total = luminance(trianglePower);
    for (const Vec3f& p : powers) total += luminance(p);
    auto share = [&](const Vec3f& p) { return total > 0 ? double(luminance(p)) / total : 0.0; };
    nlohmann::json lights = nlohmann::json::array();
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const PunctualLight& l = scene.lights[i];
        lights.push_back({{"name", l.name},
                          {"type", lightTypeName(l.type)},
                          {"from", l.node >= 0 ? "scene" : "config"},
                          {"intensity", vec(l.intensity)},
                          {"power_w", luminance(powers[i])},
                          {"share", share(powers[i])}});
    }
    r["lights"] = lights;
    r["emissive_surfaces"] = {{"power_w", luminance(trianglePower)}, {"share", share(trianglePower)}};

    const Camera& camera = job.camera();
    r["cameras"] = {{"in_scene", scene.cameras.size()},
                    {"render", {{"from", camera.node >= 0 ? "node '" + scene.nodes[size_t(camera.node)].name + "'"
                                         : settings.camera ? std::string("config")
                                                           : std::string("framing the scene's bounds")},
                                {"projection", camera.projection == Projection::Perspective ? "perspective" : "orthographic"},
                                {"position", vec(camera.position)}}}};

    nlohmann::json files = nlohmann::json::array();
    const double fps = settings.fps.value_or(kDefaultGltfFps);  // what --animation gltf would sample at
    for (const KeyframeAnimation& a : scene.animations)
        files.push_back({{"name", a.name}, {"seconds", a.endTime}, {"frames", int64_t(Animation::lastFrameAt(a.endTime, fps)) + 1}});
    uint64_t dynamicTriangles = 0;
    for (uint8_t d : scene.triangleDynamic) dynamicTriangles += d;
    nlohmann::json moved = nlohmann::json::array(), morphed = nlohmann::json::array();
    for (int n : animation.movedNodes()) moved.push_back(scene.nodes[size_t(n)].name);
    for (int n : animation.morphedNodes()) morphed.push_back(scene.nodes[size_t(n)].name);
    r["animation"] = {{"source", settings.animationPath.empty() ? "none (one still frame)" : settings.animationPath},
                      {"fps", animation.fps()},
                      {"frames", animation.lastFrame() + 1},
                      {"render_frames", {job.firstFrame(), job.lastFrame()}},
                      {"gltf_animations", files},
                      {"moved_nodes", moved},
                      {"morphed_nodes", morphed},
                      {"dynamic_triangles", dynamicTriangles},
                      {"dynamic_fraction", scene.triangleCount() ? double(dynamicTriangles) / scene.triangleCount() : 0.0},
                      {"bounds", {{"min", vec(scene.animationBounds.lower)}, {"max", vec(scene.animationBounds.upper)}}},
                      {"diagonal", scene.animationBounds.extent()}};
    r["radius"] = {{"value", settings.estimator.radius},
                   {"from", settings.radiusGiven ? "settings" : "default: 1.5 % of the animation's diagonal"}};
    r["warnings"] = warnings.messages;
    return r;
}

std::string inspectionText(const nlohmann::json& r) {
    std::string out;
    auto line = [&](const std::string& text) { out += text + "\n"; };
    auto triple = [](const nlohmann::json& v) {
        return number(v[0].get<double>()) + " " + number(v[1].get<double>()) + " " + number(v[2].get<double>());
    };
    const auto& s = r["scene"];
    line("scene      " + s["file"].get<std::string>());
    line("  " + std::to_string(s["mesh_instances"].get<uint64_t>()) + " mesh instances, " +
         std::to_string(s["nodes"].get<uint64_t>()) + " nodes, " + std::to_string(s["triangles"].get<uint64_t>()) +
         " triangles, " + std::to_string(s["vertices"].get<uint64_t>()) + " vertices; bounds " +
         triple(s["bounds"]["min"]) + " to " + triple(s["bounds"]["max"]) + " (diagonal " +
         number(s["diagonal"].get<double>()) + ")");
    const auto& m = r["materials"];
    line("materials  " + std::to_string(m["used"].get<uint64_t>()) + " used of " + std::to_string(m["count"].get<uint64_t>()) +
         "; albedo " + triple(m["albedo_min"]) + " to " + triple(m["albedo_max"]) + "; " +
         std::to_string(m["emissive"].get<uint64_t>()) + " emissive (" + std::to_string(m["emissive_triangles"].get<uint64_t>()) +
         " triangles, " + number(100 * r["emissive_surfaces"]["share"].get<double>(), "%.1f") + " % of the power)");
    line("lights     " + std::to_string(r["lights"].size()));
    for (const auto& l : r["lights"])
        line("  " + l["type"].get<std::string>() + " '" + l["name"].get<std::string>() + "' (" + l["from"].get<std::string>() +
             "): " + number(l["power_w"].get<double>()) + " W, " + number(100 * l["share"].get<double>(), "%.1f") +
             " % of the power");
    const auto& c = r["cameras"];
    line("camera     " + c["render"]["projection"].get<std::string>() + ", from " + c["render"]["from"].get<std::string>() +
         " (" + std::to_string(c["in_scene"].get<uint64_t>()) + " in the scene)");
    const auto& a = r["animation"];
    line("animation  " + a["source"].get<std::string>() + ": " + std::to_string(a["frames"].get<int64_t>()) + " frames at " +
         number(a["fps"].get<double>()) + " fps (rendering " + std::to_string(a["render_frames"][0].get<int>()) + ":" +
         std::to_string(a["render_frames"][1].get<int>()) + ")");
    for (const auto& g : a["gltf_animations"])
        line("  glTF animation '" + g["name"].get<std::string>() + "': " + number(g["seconds"].get<double>()) + " s, " +
             std::to_string(g["frames"].get<int64_t>()) + " frames");
    std::string moved;
    for (const auto& n : a["moved_nodes"]) moved += (moved.empty() ? "" : ", ") + n.get<std::string>();
    for (const auto& n : a["morphed_nodes"]) moved += (moved.empty() ? "" : ", ") + n.get<std::string>() + " (morphs)";
    line("  moving: " + (moved.empty() ? std::string("nothing") : moved) + "; " +
         std::to_string(a["dynamic_triangles"].get<uint64_t>()) + " triangles (" +
         number(100 * a["dynamic_fraction"].get<double>(), "%.1f") + " % of the scene); bounds over the animation " +
         triple(a["bounds"]["min"]) + " to " + triple(a["bounds"]["max"]));
    line("radius     " + number(r["radius"]["value"].get<double>()) + " (" + r["radius"]["from"].get<std::string>() + ")");
    line("warnings   " + std::to_string(r["warnings"].size()));
    for (const auto& w : r["warnings"]) line("  " + w.get<std::string>());
    return out;
}

}  // namespace qsgi
