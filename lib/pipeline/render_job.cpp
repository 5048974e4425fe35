#include "pipeline/render_job.h"

#include <tbb/global_control.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <climits>
#include <iterator>
#include <optional>
#include <set>
#include <stdexcept>

#include "estimate/estimator.h"
#include "estimate/final_gather.h"
#include "estimate/impact_count.h"
#include "estimate/two_pass_lighting.h"
#include "output/asset_sink.h"
#include "output/image_sink.h"
#include "output/ply_sink.h"
#include "output/usd_sink.h"
#include "scene/gltf_document.h"
#include "output/timing_log.h"
#include "output/output_directory.h"
#include "output/run_folder.h"
#include "pipeline/render_options.h"
#include "pipeline/output_frame_solver.h"
#include "pipeline/run_fingerprint.h"
#include "scene/gltf_loader.h"
#include "scene/back_sides.h"
#include "scene/contact_refinement.h"
#include "scene/mesh_refinement.h"
#include "trace/photon_tracer.h"
#include "util/input_file.h"
#include "util/json_file.h"
#include "util/memory.h"
#include "util/stopwatch.h"

namespace qsgi {

namespace fs = std::filesystem;

namespace {

// The config's look-at camera, else --camera N, else the scene's first camera, else one that
// frames the scene (with a warning).
Camera resolveCamera(const RenderSettings& s, const Scene& scene, Warnings& warnings) {
    if (s.camera) {
        try {
            return lookAtCamera(Vec3f(Vec3d(s.camera->position) - scene.worldOrigin),
                                Vec3f(Vec3d(s.camera->target) - scene.worldOrigin), s.camera->up, s.camera->yfov);
        } catch (const std::invalid_argument& e) {
            throw InputError(s.configPath.empty() ? "config" : s.configPath, "camera", e.what());
        }
    }
    if (s.cameraIndex) {
        const int i = *s.cameraIndex;
        if (i < 0 || i >= int(scene.cameras.size()))
            throw InputError(s.scenePath, "--camera " + std::to_string(i),
                             "no such camera (the file has " + std::to_string(scene.cameras.size()) + ")");
        if (!scene.cameras[i])
            throw InputError(s.scenePath, "--camera " + std::to_string(i), "the camera is not perspective or no node in the scene uses it");
        return *scene.cameras[i];
    }
    if (scene.camera) return *scene.camera;
    if (s.writeExr || s.writePng)
        warnings.add(s.scenePath + ": no camera in the scene or config; using one that frames the scene's bounds");
    return framingCamera(scene.animationBounds, float(s.width) / float(s.height));
}

}  // namespace

namespace {
// Frame 0's look ahead (FrameSolver::lookAhead): up to four steps between consecutive frames,
// evenly spread over the frames after `first` up to `last`, so that a mover that pauses or turns
// is judged by most of its path, not its first step.
std::vector<std::pair<Pose, Pose>> sampledSteps(const Animation& animation, int first, int last) {
    constexpr int kSteps = 4;
    std::vector<std::pair<Pose, Pose>> steps;
    const int count = last - first;  // steps first→first+1 … last−1→last
    for (int k = 0; k < std::min(kSteps, count); ++k) {
        const int from = first + int((int64_t(k) * count) / std::min(kSteps, count));
        steps.emplace_back(animation.poseAt(from), animation.poseAt(from + 1));
    }
    return steps;
}

// The memory a rendered triangle takes at least (issue 48): the scene's arrays (16 bytes a
// triangle, about 60 a vertex, half a vertex a triangle), the BVH (about 64) and the second pass's
// per-vertex state (the gather's 16 kept probes, 256 bytes a vertex). A refinement that would make
// more triangles than the usable memory holds at this rate is refused while it counts, before it
// fills the memory.
constexpr uint64_t kBytesPerRenderedTriangle = 256;

size_t refinedTriangleLimit() {
    return size_t(std::min<uint64_t>(uint64_t(kMaxRefinedTriangles), usableMemory().bytes / kBytesPerRenderedTriangle));
}

[[noreturn]] void refuseRefinement(const std::string& option, double length, const char* advice = "choose a longer length") {
    const MemoryLimit memory = usableMemory();
    const size_t limit = refinedTriangleLimit();
    char text[400];
    std::snprintf(text, sizeof text, "%g would make more than %zu triangles, the most %s (at %llu bytes a triangle, at least, "
                  "in the %s of memory %s): %s",
                  length, limit, double(limit) >= kMaxRefinedTriangles ? "a run holds" : "the memory holds",
                  static_cast<unsigned long long>(kBytesPerRenderedTriangle), formatBytes(memory.bytes).c_str(), memory.source.c_str(),
                  advice);
    throw InputError(option, "", text);
}
}  // namespace

RenderJob::RenderJob(RenderSettings settings, Warnings& warnings) : settings_(std::move(settings)) {
    validateSettings(settings_);
    loadScene(warnings);
    resolveAnimation();
    refineScene();
    describeScene(warnings);
    resolveFrames();
    fingerprint_ = runFingerprint(settings_, scene_, source_.fingerprintBytes(scene_), camera_);
    preflight();
}

void RenderJob::loadScene(Warnings& warnings) {
    // One read of the file: the scene is built from it, and with --gltf-out the asset is made from
    // it too, so that the asset is the file the render read even if it changes on disk meanwhile.
    auto document = std::make_shared<const GltfDocument>(readGltfDocument(settings_.scenePath, warnings));
    scene_ = loadGltfScene(*document, settings_.scenePath, warnings, GltfReadOptions{settings_.strict});
    for (const tinygltf::Mesh& mesh : document->model.meshes) meshNames_.push_back(mesh.name);  // asset.usda's names
    if (settings_.writeGltf) assetDocument_ = std::move(document);
    else document.reset();  // the scene holds what it needs: the file's buffers go
    for (PunctualLight light : settings_.extraLights) {
        light.position = Vec3f(Vec3d(light.position) - scene_.worldOrigin);
        scene_.lights.push_back(light);
    }
    if (settings_.environment.given()) {
        const EnvironmentSettings& e = settings_.environment;
        auto light = std::make_shared<const EnvironmentLight>(
            e.sky ? EnvironmentLight::uniform(*e.sky) : EnvironmentLight::fromImage(e.image, e.intensity, e.rotationDegrees));
        // A black sky or map lights nothing: kept, it would cast shadow rays for nothing (and its
        // sampling has no density to draw from).
        if (luminance(light->integral()) > 0) scene_.environment = std::move(light);
    }
    if (scene_.triangleCount() == 0) throw InputError(settings_.scenePath, "", "the scene has no triangles");
    for (uint32_t t = 0; t < scene_.triangleCount() && !lit_; ++t)
        lit_ = scene_.materials[scene_.triangleMaterial[t]].isEmissive() && scene_.triangleArea(t) > 0;
    for (const PunctualLight& l : scene_.lights) lit_ = lit_ || luminance(l.intensity) > 0;
    lit_ = lit_ || scene_.environment != nullptr;
}

void RenderJob::resolveAnimation() {
    source_ = AnimationSource::resolve(settings_);
    animation_ = source_.load(scene_, settings_.fps.value_or(kDefaultGltfFps));
    if (!source_.still()) checkLightsAreStatic(scene_, animation_, source_.name());
    scene_.setRestPose(animation_.poseAt(0));
    inputVertices_ = scene_.vertexCount();
}

void RenderJob::refineScene() {
    auto poseAt = [&](int frame) { return animation_.poseAt(frame); };
    if (settings_.subdivide > 0) {
        const size_t estimate = estimatedRefinedTriangles(scene_, settings_.subdivide);
        if (double(estimate) > kMaxRefinedTriangles) {
            char text[200];
            std::snprintf(text, sizeof text, "%g would refine %zu triangles into about %.3g, more than %.0e: choose a longer length",
                          double(settings_.subdivide), scene_.triangleCount(), double(estimate), kMaxRefinedTriangles);
            throw InputError("subdivide (--subdivide)", "", text);
        }
        if (!refineMesh(scene_, settings_.subdivide, refinedTriangleLimit()))
            refuseRefinement("subdivide (--subdivide)", settings_.subdivide);
    }
    if (settings_.refineContacts > 0) {
        const double size = double(scene_.bounds().extent());
        if (double(settings_.refineContacts) < 1e-4 * size) {
            char text[200];
            std::snprintf(text, sizeof text, "%g is below 1e-4 of the scene's size (%g): its contact lines would be refined into more "
                          "triangles than a run can hold", double(settings_.refineContacts), size);
            throw InputError("refine_contacts (--refine-contacts)", "", text);
        }
        const std::optional<ContactRefinementReport> refined =
            refineContacts(scene_, settings_.refineContacts, animation_.lastFrame(), poseAt, refinedTriangleLimit());
        if (!refined) refuseRefinement("refine_contacts (--refine-contacts)", settings_.refineContacts);
        contactRefinement_ = {{"vertices_added", refined->mesh.verticesAfter - refined->mesh.verticesBefore},
                              {"poses_judged", refined->posesJudged}};
    }
    if (settings_.writeGltf) {
        // Refused now, not after the render, if the asset cannot take the bake.
        BakedAssetSettings asset;
        asset.colourSet = settings_.gltfColourSet;
        checkAssetTakesBake(*assetDocument_, scene_, asset, settings_.scenePath);
    }
    scene_.markDynamic(animation_.movedNodes(), animation_.morphedNodes());
    sweepAnimationBounds(scene_, animation_);
    // Which doubleSided surfaces get a back side (lib/scene/back_sides.h), decided on the output
    // mesh: the fit's sampling mesh takes the same, so that the fit pairs their instances.
    backSided_ = instancesWithBackSides(scene_);
    if (settings_.vertexFit == VertexFitKind::LeastSquares) {
        std::optional<Scene> samples =
            VertexFitStage::samplingMesh(scene_, animation_, backSided_, defaultRadius(scene_), refinedTriangleLimit());
        if (!samples)
            refuseRefinement("vertex_fit (--vertex-fit): its samples, edges within R of a contact split to R/2 with R", defaultRadius(scene_),
                             "use --vertex-fit point");
        fit_.emplace(std::move(*samples));
    }
}

void RenderJob::describeScene(Warnings& warnings) {
    checkLightPowerAndPlace(scene_, settings_.scenePath, settings_.configPath);
    if (!source_.still()) checkSceneExtent(scene_.positions, scene_.animationBounds, source_.name(), "frames");
    camera_ = resolveCamera(settings_, scene_, warnings);
    if (!settings_.radiusGiven) settings_.estimator.radius = defaultRadius(scene_);
    resolution_ = qsgi::meshResolution(scene_, settings_.estimator.radius);
    if (resolution_.coarseAreaShare() >= kCoarseAreaWarning) {
        char text[400];
        std::snprintf(text, sizeof text,
                      "%zu of %zu triangles have an edge longer than 4 r = %g (the longest %g): they cover %.1f %% of the "
                      "surface with %zu vertices, and radiosity lives at vertices, so no shadow or patch of light smaller "
                      "than them can show (--subdivide %g refines them to 2 r; a larger --radius also matches the two)",
                      resolution_.coarseTriangles, scene_.triangleCount(), resolution_.edgeLimit, resolution_.longestEdge,
                      100 * resolution_.coarseAreaShare(), resolution_.coarseVertices, resolution_.edgeLimit / 2);
        warnings.add(settings_.scenePath + ": " + text);
    }
    // Last, after every refinement (which would take a back side for a surface touching its front)
    // and after the mesh's resolution, which describes the file's mesh.
    addBackSides(scene_, backSided_);
}

void RenderJob::resolveFrames() {
    first_ = 0;
    last_ = animation_.lastFrame();
    if (settings_.frames) {
        first_ = settings_.frames->first;
        last_ = settings_.frames->last < 0 ? animation_.lastFrame() : settings_.frames->last;
        if (last_ > animation_.lastFrame()) {
            // Which animation ends there and why ("" for a still scene), then the file's unplayed ones.
            std::string note = animation_.lastFrameReason();
            const std::string unplayed = unplayedAnimationsNote();
            if (!unplayed.empty()) note += (note.empty() ? "" : "; ") + unplayed;
            throw InputError(settings_.framesSource.empty() ? "command line" : settings_.framesSource, "frames",
                             std::to_string(first_) + ":" + std::to_string(last_) + " reaches past the " +
                                 (source_.still() ? std::string("last frame, 0 (a still scene has one frame)")
                                                  : "animation's last frame " + std::to_string(animation_.lastFrame())) +
                                 (note.empty() ? "" : " (" + note + ")"));
        }
    }
    // A camera hung from a node the animation scales to zero has no direction: refused before
    // any frame is written, naming the first such frame (a hidden node is fine, a hidden camera
    // is not).
    if (camera_.node >= 0 && !animation_.movedNodes().empty())
        for (int frame = first_; frame <= last_; ++frame) {
            if (!hasDirection(cameraAt(frame)))
                throw InputError(source_.name(), "frame " + std::to_string(frame),
                                 "the camera's node '" + scene_.nodes[size_t(camera_.node)].name +
                                     "' has a singular transform (a zero scale), so the camera has no direction");
        }
}

void RenderJob::preflight() const {
    // The gather's kept hits (issue 48), by the second pass's own count.
    const Scene& solved = fit_ ? fit_->samplingScene() : scene_;
    const LightingSettings lighting = settings_.lighting.resolvedFor(solved.vertexCount());
    const bool updates = last_ > first_ && !settings_.update.fullRecompute;  // else every frame streams its rays
    const TwoPassLighting::KeptHits kept = TwoPassLighting::keptGatherHits(lighting, solved.vertexCount(), updates);
    if (lighting.gathers())
        refuseBeyondMemory(kept.bytes, "gather (--gather)", "",
                           "the gather's kept hits (" + std::to_string(kept.perVertex) + " a vertex, at " +
                               std::to_string(sizeof(GatherHit)) + " bytes, for " + std::to_string(solved.vertexCount()) + " vertices)");
}

void RenderJob::refuseIfUnlit() const {
    if (!lit_)
        throw InputError(settings_.scenePath, "",
                         "the scene has no lights (no emissive material, no KHR_lights_punctual light); light it with "
                         "\"lights\" in a --config file, a sky (--sky R,G,B) or an HDR environment map (--environment FILE)");
}

std::string RenderJob::unplayedAnimationsNote() const {
    if (scene_.animations.empty() || source_.gltf()) return "";
    const double fps = settings_.fps.value_or(kDefaultGltfFps);
    const size_t count = scene_.animations.size();
    std::string note = "the scene file has " + std::to_string(count) + (count == 1 ? " animation: " : " animations: ");
    for (size_t a = 0; a < count; ++a) {
        const KeyframeAnimation& animation = scene_.animations[a];
        char frames[96];
        std::snprintf(frames, sizeof frames, "%lld frames at %g fps",
                      static_cast<long long>(Animation::lastFrameAt(animation.endTime, fps)) + 1, fps);
        note += (a ? ", " : "") + (animation.name.empty() ? "#" + std::to_string(a) : "'" + animation.name + "'") +
                (count > 1 ? " (gltf:" + std::to_string(a) + ")" : "") + ", " + frames;
    }
    return note + "; --animation gltf plays " + (count == 1 ? "it" : "them all at once");
}

Camera RenderJob::cameraAt(int frame) const {
    // A camera hung from a node follows it (channels on camera nodes move the view only).
    if (camera_.node < 0) return camera_;
    return placeCamera(camera_, scene_.worldTransforms(animation_.localsAt(frame))[size_t(camera_.node)],
                       scene_.worldOrigin);
}

namespace {
// The last guard before a frame's files are made (issue 48): lights are checked against float's
// range before the render, but a point light a hair from a surface (I/d²) is not bounded until the
// frame is posed. A value that is not finite refuses the frame — no file with Inf, no exit 0.
void refuseNonFinite(const SolvedFrame& frame, const std::string& scenePath) {
    const VertexRadiosity& r = frame.result;
    for (size_t v = 0; v < r.radiosity.size(); ++v)
        if (!isFinite(r.radiosity[v]) || (v < r.irradiance.size() && !isFinite(r.irradiance[v])))
            throw InputError(scenePath, "frame " + std::to_string(frame.frame) + ", vertex " + std::to_string(v),
                             "its light is beyond float's range (a light too strong for the scene's scale, or one almost "
                             "touching a surface): scale the light's units down");
}
}  // namespace

FolderExpectations folderExpectations(const RenderSettings& settings, const RunFingerprint& fingerprint) {
    FolderExpectations expected;
    expected.digest = fingerprint.digest;
    expected.parts = fingerprint.parts;
    expected.differences = fingerprintDifferences;
    expected.frameExtensions = {"ply"};
    if (settings.writeExr) expected.frameExtensions.push_back("exr");
    if (settings.writePng) expected.frameExtensions.push_back("png");
    expected.resume = settings.resume;
    expected.overwrite = settings.overwrite;
    return expected;
}

RunOutcome RenderJob::run(const RunObserver& observer) {
    refuseIfUnlit();
    std::optional<tbb::global_control> threadLimit;
    if (settings_.threads > 0) threadLimit.emplace(tbb::global_control::max_allowed_parallelism, size_t(settings_.threads));
    auto warn = [&](const std::string& message) {
        if (observer.onWarning) observer.onWarning(message);
    };

    RunFolder folder(settings_.outDir, folderExpectations(settings_, fingerprint_), "qsgi render", warn);
    RunOutcome outcome;
    outcome.filesReplaced = folder.filesReplaced();
    const int start = folder.startFrame(first_, last_);
    TimingLog log;
    log.config = optionValues(settings_, OptionSelection::Logged);
    log.degenerateTriangles = ImpactCount(scene_).degenerateTriangles();
    log.photons = settings_.trace.photons;
    log.config["threads"] = settings_.threads > 0 ? settings_.threads
                                                  : int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    log.scene = settings_.scenePath;
    log.vertices = scene_.frontVertexCount();
    log.triangles = scene_.frontTriangleCount();
    log.backSideVertices = scene_.vertexCount() - scene_.frontVertexCount();
    for (size_t v = 0; v < scene_.frontVertexCount(); ++v) log.dynamicVertices += scene_.vertexDynamic[v];
    log.lights = scene_.lights.size();
    log.animationDiagonal = scene_.animationBounds.extent();
    log.inputVertices = inputVertices_;
    log.contactRefinement = contactRefinement_;
    log.fitSamples = fit_ ? fit_->samplingScene().vertexCount() : 0;
    log.inputsFingerprint = fingerprint_.digest;
    log.inputs = fingerprint_.parts;
    const RunFolder::Started started = folder.startLog(std::move(log), start, last_);
    outcome.framesResumed = settings_.resume ? started.framesOutside : 0;
    outcome.framesKept = settings_.resume ? 0 : started.framesOutside;
    outcome.framesRemoved = started.framesRemoved;
    outcome.nextFrame = start;
    const std::vector<std::unique_ptr<FrameSink>> sinks = makeFrameSinks();
    auto finish = [&] {
        for (const std::unique_ptr<WholeRunSink>& sink : makeWholeRunSinks()) {
            WholeRunReport report = sink->make(folder.directory());
            for (const std::string& w : report.warnings) warn(w);
            outcome.wholeRunFiles.push_back(std::move(report));
        }
    };
    if (start > last_) {  // resumed with nothing left to do
        finish();
        return outcome;
    }

    EmbreeDevice device;
    const FrameSolverSettings solverSettings{settings_.estimator, effectiveTrace(settings_.trace), settings_.lighting,
                                             settings_.update};
    OutputFrameSolver solver(scene_, fit_ ? &*fit_ : nullptr, device, solverSettings);
    // The frame's solve: what the sinks see, and its record.
    auto solveFrame = [&](int frame, bool updateFollows) {
        OutputFrameSolver::Result solved = solver.solve(frame, animation_.poseAt(frame), updateFollows);
        if (solved.fitFallbacks > 0)
            warn("frame " + std::to_string(frame) + ": the vertex fit's solve failed for " + std::to_string(solved.fitFallbacks) +
                 " meshes, which keep their point values");
        refuseNonFinite(solved.frame, settings_.scenePath);
        return solved;
    };

    // Previews are tonemapped as frame 0 of the animation is (docs/design.md §6.0), so that any frame
    // range writes the bytes one sequential run would. A run that starts later computes frame 0
    // once for it, then the state at its first frame from scratch.
    bool calibrated = false;
    auto calibrate = [&](const SolvedFrame& frame0) {
        for (const std::unique_ptr<FrameSink>& sink : sinks) sink->calibrate(frame0);
        calibrated = true;
    };
    if (start > 0) {
        calibrate(solveFrame(0, false).frame);
        solver.reset();
    }

    const int count = last_ - start + 1;
    int current = start;  // the frame being solved, for the stage reports
    auto stage = [&](const char* name, uint64_t done, uint64_t total) {
        if (observer.onStage) observer.onStage(StageReport{current, current - start, count, name, done, total});
    };
    const FrameSolver& frames = solver.frameSolver();
    solver.frameSolver().reportStagesTo(stage);
    solver.frameSolver().lookAhead(sampledSteps(animation_, start, last_));
    const double setupSeconds = started_.seconds();
    for (int frame = start; frame <= last_; ++frame) {
        current = frame;
        Stopwatch frameClock;
        OutputFrameSolver::Result result = solveFrame(frame, frame < last_);
        const SolvedFrame& solved = result.frame;
        FrameTiming& timing = result.record;
        timing.frame = frame;
        if (!calibrated) calibrate(solved);
        if (frame == start) {
            TimingLog& log = folder.log();
            log.photonsMissingScene = timing.photonsMissingScene;
            log.emittedFraction = frames.emittedFraction();
            log.emissionMeasured = true;
            const LightSampler& lights = frames.tracer().lights();
            log.setup = {{"before_first_frame_s", setupSeconds},
                         {"aimed_lights", lights.aimedLights()},
                         {"aim_s", lights.aimSeconds()}};
            const FrameSolver::TrackingDecision& tracking = frames.trackingDecision();
            if (!tracking.decision.empty())
                log.setup["tracking"] = {{"decision", tracking.decision},
                                         {"steps_judged", tracking.shares.size()},
                                         {"predicted_update_shares", tracking.shares},
                                         {"median_share", tracking.median}};
            if (const DirectLight* direct = frames.directLight())
                log.setup["light_tree"] = {{"emitters", direct->sampledEmitters()},
                                           {"lights_sampled", direct->lightsSampled()},
                                           {"bytes", direct->treeBytes()},
                                           {"build_s", direct->treeSeconds()}};
        }
        for (const std::unique_ptr<FrameSink>& sink : sinks)
            if (const char* preparing = sink->preparingStage()) {
                stage(preparing, 0, 0);
                timing.renderSeconds += sink->prepare(solved);
            }

        Stopwatch encoding;
        stage("writing", 0, 0);
        // Every file encoded before any is written: an encoder that fails leaves nothing behind.
        // Then the frame is on disk whole or not at all (RunFolder::commitFrame).
        std::vector<EncodedFile> files;
        for (const std::unique_ptr<FrameSink>& sink : sinks) sink->encode(solved, files);
        timing.writeSeconds = encoding.seconds();
        folder.commitFrame(frame, files, std::move(timing));
        outcome.nextFrame = frame + 1;
        ++outcome.framesWritten;
        if (observer.onFrame)
            observer.onFrame(FrameReport{frame, frame - start, count, frameClock.seconds(),
                                double(folder.log().photonsMissingScene) / double(std::max<uint64_t>(settings_.trace.photons, 1))});
        if (frame < last_ && observer.stopRequested && observer.stopRequested()) {
            outcome.interrupted = true;
            return outcome;
        }
    }
    finish();
    return outcome;
}

std::vector<std::unique_ptr<FrameSink>> RenderJob::makeFrameSinks() const {
    std::vector<std::unique_ptr<FrameSink>> sinks;
    // In the order the log lists a frame's files: PLY, EXR, PNG.
    sinks.push_back(std::make_unique<PlySink>());
    if (settings_.writeExr || settings_.writePng) {
        ImageSinkSettings image;
        image.exr = settings_.writeExr;
        image.exrHalf = settings_.exrHalf;
        image.png = settings_.writePng;
        image.exposure = settings_.exposure;
        image.image = ImageSettings{settings_.width, settings_.height, settings_.samplesPerPixel, settings_.trace.seed};
        image.cameraAt = [this](int frame) { return cameraAt(frame); };
        image.metadataAt = [this](int frame) {
            ImageMetadata m;
            m.strings = {{"qsgi:estimator", estimatorName(settings_.estimator.kind)}, {"qsgi:version", QSGI_VERSION},
                         {"qsgi:scene", settings_.scenePath},
                         {"qsgi:seed", std::to_string(settings_.trace.seed)}, {"Software", std::string("qsgi ") + QSGI_VERSION}};
            m.ints = {{"qsgi:frame", frame}, {"qsgi:photons", int(std::min<uint64_t>(settings_.trace.photons, INT32_MAX))},
                      {"qsgi:spp", settings_.samplesPerPixel}};
            // 0: the estimator has no radius (impact count)
            m.floats = {{"qsgi:radius", settings_.estimator.kind == EstimatorKind::ImpactCount ? 0.0f : settings_.estimator.radius}};
            m.ints.emplace_back("qsgi:k", settings_.estimator.kind == EstimatorKind::PhotonMap ? settings_.estimator.photonMap.k : 0);
            return m;
        };
        sinks.push_back(std::make_unique<ImageSink>(std::move(image)));
    }
    return sinks;
}

std::vector<std::unique_ptr<WholeRunSink>> RenderJob::makeWholeRunSinks() const {
    std::vector<std::unique_ptr<WholeRunSink>> sinks;
    // A run of --frames-only (a Slurm chunk) leaves the whole-run files to the run that has every frame.
    if (settings_.writeGltf && !settings_.framesOnly) {
        AssetSinkSettings asset;
        asset.document = assetDocument_;
        asset.first = first_;
        asset.last = last_;
        asset.fps = animation_.fps();
        asset.asset.colourSet = settings_.gltfColourSet;
        asset.asset.playedAnimation = source_.playedGltfAnimation(scene_);
        asset.asset.assetFolder = settings_.outDir;
        // A transform file's motion becomes the asset's node animation; a glTF animation is the file's already.
        asset.asset.playedAll = source_.gltf() && source_.gltfIndex() < 0 && asset.asset.playedAnimation < 0;
        if (source_.transformFile()) asset.asset.firstPose = animation_.localsAt(first_);
        if (source_.transformFile() && last_ > first_) {
            for (const int node : animation_.movedNodes()) asset.motion.push_back(NodeMotion{node, {}});
            for (int frame = first_; frame <= last_; ++frame) {
                const std::vector<Transform> locals = animation_.localsAt(frame);
                for (NodeMotion& m : asset.motion) m.frames.push_back(decomposeTrs(locals[size_t(m.node)]));
            }
        }
        sinks.push_back(std::make_unique<AssetSink>(scene_, std::move(asset)));
    }
    if (settings_.writeUsd && !settings_.framesOnly) {
        UsdAssetSettings usd;
        usd.first = first_;
        usd.last = last_;
        usd.fps = animation_.fps();
        usd.source = settings_.scenePath;
        usd.meshNames = meshNames_;
        usd.nodeWorldAt = [this](int frame) { return scene_.worldTransforms(animation_.localsAt(frame)); };
        // Frames held while writing: a group of meshes at a time, each group reading every PLY once.
        usd.memoryBudget = std::min<uint64_t>(uint64_t(1) << 30, usableMemory().bytes / 8);
        sinks.push_back(std::make_unique<UsdSink>(scene_, std::move(usd)));
    }
    return sinks;
}

}  // namespace qsgi
