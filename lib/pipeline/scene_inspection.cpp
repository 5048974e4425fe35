#include "pipeline/scene_inspection.h"

#include <algorithm>
#include <cstdio>
#include <set>

#include "output/folder_survey.h"
#include "util/json_file.h"
#include "pipeline/render_options.h"
#include "trace/light_sampler.h"

namespace qsgi {

namespace {

// A path as pathJson records it, for the text report.
std::string shownPath(const nlohmann::json& path) {
    return path.is_string() ? path.get<std::string>() : path.at("text").get<std::string>();
}

nlohmann::json vec(const Vec3f& v) { return {v.x, v.y, v.z}; }
// A position as the file and the PLY give it: the scene is held re-centred on its worldOrigin.
nlohmann::json world(const Vec3f& p, const Scene& scene) {
    const Vec3d w = Vec3d(p) + scene.worldOrigin;
    return {w.x, w.y, w.z};
}

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

std::string frameRange(int first, int last) { return std::to_string(first) + ":" + std::to_string(last); }

// What the output folder holds and what this render would do with it; reads, never writes.
nlohmann::json outputFolderReport(const RenderJob& job) {
    using Holds = OutputFolderSurvey::Holds;
    const RenderSettings& s = job.settings();
    const OutputFolderSurvey survey = surveyOutputFolder(s.outDir, folderExpectations(s, job.fingerprint()));
    const std::string range = frameRange(job.firstFrame(), job.lastFrame());
    nlohmann::json r = {{"path", pathJson(s.outDir)}, {"frame_files", survey.frameFiles.size()}};
    std::string render;
    if (survey.holds == Holds::Nothing) {
        r["state"] = survey.exists ? "empty" : "absent";
        render = "renders frames " + range + (survey.exists ? " into it" : ", creating it");
    } else if (survey.holds == Holds::ThisRun) {
        r["state"] = "this run";
        std::set<int> complete;
        for (const FrameTiming& f : survey.completeFrames) complete.insert(f.frame);
        r["complete_frames"] = complete;
        nlohmann::json failing = nlohmann::json::array();
        for (const OutputFolderSurvey::FailedFrame& f : survey.failedFrames)
            failing.push_back({{"frame", f.frame}, {"problem", f.reason}});
        r["failing_frames"] = failing;
        const int next = firstIncompleteFrame(survey, job.firstFrame(), job.lastFrame());
        if (s.resume)
            render = next > job.lastFrame() ? "nothing: frames " + range + " are complete (--resume)"
                                            : "resumes at frame " + std::to_string(next) + " and renders " +
                                                  frameRange(next, job.lastFrame()) + " (--resume)";
        else
            render = "renders frames " + range + " again (the same bytes) and keeps the folder's other frames of this run" +
                     (next > job.firstFrame() ? "; --resume would start at frame " + std::to_string(next) : "");
    } else {
        r["state"] = survey.holds == Holds::AnotherRun ? "another run" : "frame files without timing.json";
        r["differences"] = survey.differences;
        render = s.overwrite ? "unlinks the earlier run's " + std::to_string(survey.frameFiles.size()) +
                                   " frame files and timing.json (--overwrite), then renders frames " + range
                             : std::string("refuses: ") + outputFolderRefusal(survey, folderExpectations(s, job.fingerprint()))->what();
    }
    if (!survey.failedFrames.empty() && survey.holds == Holds::ThisRun)
        render += "; " + std::to_string(survey.failedFrames.size()) +
                  (survey.failedFrames.size() == 1 ? " frame it lists is" : " frames it lists are") +
                  " not as its timing.json records them: computed again within the frames rendered, removed outside them";
    if (!job.hasLight()) render = "refuses: the scene has no lights";
    r["render"] = render;
    return r;
}

}  // namespace

nlohmann::json inspectRender(const RenderJob& job, const Warnings& warnings) {
    const Scene& scene = job.scene();
    const RenderSettings& settings = job.settings();
    const Animation& animation = job.animation();
    nlohmann::json r;

    const Bounds3f bounds = scene.bounds();
    // The scene as the file gives it: the back sides of doubleSided surfaces (lib/scene/back_sides.h),
    // which the job has added, are counted apart.
    const uint32_t triangles = uint32_t(scene.frontTriangleCount());
    r["scene"] = {{"file", pathJson(settings.scenePath)},
                  {"mesh_instances", scene.frontInstanceCount()},
                  {"nodes", scene.nodes.size()},
                  {"triangles", triangles},
                  {"vertices", scene.frontVertexCount()},
                  {"bounds", {{"min", world(bounds.lower, scene)}, {"max", world(bounds.upper, scene)}}},
                  {"diagonal", bounds.extent()}};

    // Materials as the render uses them: albedo range and emitters, over triangles that have area.
    std::set<uint32_t> used, emissive;
    uint64_t emissiveTriangles = 0;
    for (uint32_t t = 0; t < triangles; ++t) {
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
    // What the used materials read besides their factors (issue 57, docs/inputs.md).
    uint64_t textured = 0, mask = 0, blend = 0, doubleSided = 0, transmissive = 0, emissionTextured = 0;
    for (uint32_t m : used) {
        const Material& material = scene.materials[m];
        textured += material.baseColour.used();
        mask += material.alphaMode == AlphaMode::Mask;
        blend += material.alphaMode == AlphaMode::Blend;
        doubleSided += material.doubleSided;
        transmissive += material.transmission > 0;
        emissionTextured += material.isEmissive() && material.emissive.used();
    }
    uint64_t textureBytes = 0;
    if (scene.textures)
        for (const Texture& t : *scene.textures) textureBytes += t.bytes();
    r["materials"] = {{"count", scene.frontMaterialCount()},
                      {"used", used.size()},
                      {"albedo_min", vec(lowest)},
                      {"albedo_max", vec(highest)},
                      {"emissive", emissive.size()},
                      {"emissive_triangles", emissiveTriangles},
                      {"base_colour_textured", textured},
                      {"alpha_mask", mask},
                      {"alpha_blend", blend},
                      {"double_sided", doubleSided},
                      // the vertices a render lights twice: the cost of the back sides
                      {"back_side_vertices", scene.vertexCount() - scene.frontVertexCount()},
                      {"transmissive", transmissive},
                      {"emission_textured", emissionTextured},
                      {"vertex_colours", !scene.vertexColours.empty()},
                      {"texture_bytes", textureBytes}};

    // Each emitter's power as the photon tracer shares photons among them (unaimed).
    const LightSampler sampler(scene, 1, scene.sceneEpsilon());
    const std::vector<Vec3f> powers = sampler.lightPowers(scene.lights.size());
    const Vec3f trianglePower = sampler.emissiveTrianglePower();
    const Vec3f environmentPower = sampler.environmentPower();
    double total = luminance(trianglePower) + luminance(environmentPower);
    for (const Vec3f& p : powers) total += luminance(p);
    auto share = [&](const Vec3f& p) { return total > 0 ? double(luminance(p)) / total : 0.0; };
    nlohmann::json lights = nlohmann::json::array();
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const PunctualLight& l = scene.lights[i];
        lights.push_back({{"name", l.name},
                          {"type", lightTypeName(l.type)},
                          {"from", l.node >= 0 ? "scene" : "config"},
                          {"position", l.type == LightType::Directional ? nlohmann::json(nullptr) : world(l.position, scene)},
                          {"intensity", vec(l.intensity)},
                          {"power_w", luminance(powers[i])},
                          {"share", share(powers[i])}});
    }
    r["lights"] = lights;
    r["lit"] = job.hasLight();
    r["emissive_surfaces"] = {{"power_w", luminance(trianglePower)}, {"share", share(trianglePower)}};
    if (scene.environment) {
        const EnvironmentSettings& e = settings.environment;
        r["environment"] = {{"type", scene.environment->isUniform() ? "sky" : "environment"},
                            {"image", e.image.empty() ? nlohmann::json(nullptr) : pathJson(e.image)},
                            {"pixels", {scene.environment->width(), scene.environment->height()}},
                            {"rotation", e.rotationDegrees},
                            // What enters the bounding sphere of the animation, π R² ∫ L dω.
                            {"power_w", luminance(environmentPower)},
                            {"share", share(environmentPower)}};
    } else {
        r["environment"] = nullptr;
    }

    const Camera& camera = job.camera();
    r["cameras"] = {{"in_scene", scene.cameras.size()},
                    {"render", {{"from", camera.node >= 0 ? (scene.nodes[size_t(camera.node)].name.empty() ? "node #" + std::to_string(camera.node) : "node '" + scene.nodes[size_t(camera.node)].name + "'")
                                         : settings.camera ? std::string("config")
                                                           : std::string("framing the scene's bounds")},
                                {"projection", camera.projection == Projection::Perspective ? "perspective" : "orthographic"},
                                {"position", world(camera.position, scene)}}}};

    nlohmann::json files = nlohmann::json::array();
    const double fps = settings.fps.value_or(kDefaultGltfFps);  // what --animation gltf would sample at
    for (const KeyframeAnimation& a : scene.animations)
        files.push_back({{"name", a.name}, {"seconds", a.endTime}, {"frames", int64_t(Animation::lastFrameAt(a.endTime, fps)) + 1}});
    uint64_t dynamicTriangles = 0;
    for (uint32_t t = 0; t < triangles; ++t) dynamicTriangles += scene.triangleDynamic[t];
    nlohmann::json moved = nlohmann::json::array(), morphed = nlohmann::json::array();
    for (int n : animation.movedNodes()) moved.push_back(scene.nodes[size_t(n)].name);
    for (int n : animation.morphedNodes()) morphed.push_back(scene.nodes[size_t(n)].name);
    r["animation"] = {{"source", settings.animationPath.empty() ? nlohmann::json("none (one still frame)") : pathJson(settings.animationPath)},
                      {"fps", animation.fps()},
                      {"frames", animation.lastFrame() + 1},
                      {"render_frames", {job.firstFrame(), job.lastFrame()}},
                      {"gltf_animations", files},
                      {"moved_nodes", moved},
                      {"morphed_nodes", morphed},
                      {"dynamic_triangles", dynamicTriangles},
                      {"dynamic_fraction", triangles ? double(dynamicTriangles) / triangles : 0.0},
                      {"bounds", {{"min", world(scene.animationBounds.lower, scene)}, {"max", world(scene.animationBounds.upper, scene)}}},
                      {"diagonal", scene.animationBounds.extent()}};
    const MeshResolution& mesh = job.meshResolution();
    r["mesh_resolution"] = {{"edge_limit", mesh.edgeLimit},
                            {"longest_edge", mesh.longestEdge},
                            {"coarse_triangles", mesh.coarseTriangles},
                            {"coarse_vertices", mesh.coarseVertices},
                            {"coarse_area_share", mesh.coarseAreaShare()}};
    r["radius"] = {{"value", settings.estimator.radius},
                   {"from", settings.radiusGiven ? "settings" : "default: 1.5 % of the animation's diagonal"}};
    r["animation"]["unplayed_animations"] = job.unplayedAnimationsNote();

    // The options this render sets away from their defaults (the scene's path is always set).
    // Options that only one estimator or sampler reads are compared with that estimator's or
    // sampler's defaults, so that choosing DETP does not list its default radius as a choice.
    RenderSettings defaults, alike;
    alike.estimator.kind = settings.estimator.kind;
    alike.trace.sampling.kind = settings.trace.sampling.kind;
    if (!settings.radiusGiven) alike.estimator.radius = settings.estimator.radius;
    const nlohmann::json chosen = optionValues(settings, OptionSelection::All);
    const nlohmann::json standard = optionValues(defaults, OptionSelection::All), standardAlike = optionValues(alike, OptionSelection::All);
    nlohmann::json changed = nlohmann::json::object();
    for (auto it = chosen.begin(); it != chosen.end(); ++it) {
        const nlohmann::json& base = it.key() == "estimator" || it.key() == "sampler" ? standard : standardAlike;
        if (it.key() != "scene" && (!base.contains(it.key()) || base.at(it.key()) != it.value())) changed[it.key()] = it.value();
    }
    // A radius the user gave is a choice even where it equals the default (or the estimator
    // does not read it).
    if (settings.radiusGiven) changed["radius"] = settings.estimator.radius;
    if (settings.resume) changed["resume"] = true;
    if (settings.overwrite) changed["overwrite"] = true;
    r["options_set"] = changed;

    r["output_folder"] = outputFolderReport(job);
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
    line("scene      " + shownPath(s["file"]));
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
    line("  base colour textured " + std::to_string(m["base_colour_textured"].get<uint64_t>()) + " (" +
         number(double(m["texture_bytes"].get<uint64_t>()) / (1 << 20), "%.1f") + " MiB decoded), alpha MASK " +
         std::to_string(m["alpha_mask"].get<uint64_t>()) + ", BLEND " + std::to_string(m["alpha_blend"].get<uint64_t>()) +
         ", double-sided " + std::to_string(m["double_sided"].get<uint64_t>()) + " (" +
         std::to_string(m["back_side_vertices"].get<uint64_t>()) + " back-side vertices), transmissive " +
         std::to_string(m["transmissive"].get<uint64_t>()) + ", emission textured " +
         std::to_string(m["emission_textured"].get<uint64_t>()) + "; vertex colours " +
         (m["vertex_colours"].get<bool>() ? "yes" : "no"));
    if (!r["lit"].get<bool>())
        line("lights     none: no emissive material and no light of any power; light the scene with \"lights\" in a "
             "config (docs/inputs.md), --sky R,G,B or --environment FILE before rendering");
    else
        line("lights     " + std::to_string(r["lights"].size()));
    for (const auto& l : r["lights"])
        line("  " + l["type"].get<std::string>() + " '" + l["name"].get<std::string>() + "' (" + l["from"].get<std::string>() +
             "): " + number(l["power_w"].get<double>()) + " W, " + number(100 * l["share"].get<double>(), "%.1f") +
             " % of the power");
    if (const auto& e = r["environment"]; !e.is_null())
        line("  " + e["type"].get<std::string>() + (e["image"].is_null() ? "" : " " + shownPath(e["image"])) + " (" +
             std::to_string(e["pixels"][0].get<uint32_t>()) + " x " + std::to_string(e["pixels"][1].get<uint32_t>()) +
             " pixels): " + number(e["power_w"].get<double>()) + " W into the animation's bounding sphere, " +
             number(100 * e["share"].get<double>(), "%.1f") + " % of the power");
    const auto& c = r["cameras"];
    line("camera     " + c["render"]["projection"].get<std::string>() + ", from " + c["render"]["from"].get<std::string>() +
         " (" + std::to_string(c["in_scene"].get<uint64_t>()) + " in the scene)");
    const auto& a = r["animation"];
    line("animation  " + shownPath(a["source"]) + ": " + std::to_string(a["frames"].get<int64_t>()) + " frames at " +
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
    if (!a["unplayed_animations"].get<std::string>().empty()) line("  " + a["unplayed_animations"].get<std::string>());
    line("radius     " + number(r["radius"]["value"].get<double>()) + " (" + r["radius"]["from"].get<std::string>() + ")");
    const auto& mesh = r["mesh_resolution"];
    const uint64_t coarse = mesh["coarse_triangles"].get<uint64_t>();
    line("mesh       longest edge " + number(mesh["longest_edge"].get<double>()) + "; " +
         (coarse == 0 ? std::string("no edge longer than 4 r = ") + number(mesh["edge_limit"].get<double>())
                      : std::to_string(coarse) + " triangles longer than 4 r = " + number(mesh["edge_limit"].get<double>()) +
                            " cover " + number(100 * mesh["coarse_area_share"].get<double>(), "%.1f") + " % of the surface with " +
                            std::to_string(mesh["coarse_vertices"].get<uint64_t>()) + " vertices"));
    std::string options;
    for (auto it = r["options_set"].begin(); it != r["options_set"].end(); ++it)
        options += (options.empty() ? "" : ", ") + it.key() + " " +
                   (it.value().is_string()         ? it.value().get<std::string>()
                    : it.value().is_number_float() ? number(it.value().get<double>(), "%.7g")
                                                   : it.value().dump());
    line("options    " + (options.empty() ? std::string("the defaults") : options));
    const auto& folder = r["output_folder"];
    line("output     " + shownPath(folder["path"]) + ": " + folder["state"].get<std::string>() + "; a render " +
         folder["render"].get<std::string>());
    line("warnings   " + std::to_string(r["warnings"].size()));
    for (const auto& w : r["warnings"]) line("  " + w.get<std::string>());
    return out;
}

}  // namespace qsgi
