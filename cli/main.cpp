// qsgi: the command-line host. Parses options, configures a RenderJob, reports progress and maps
// errors to exit codes (0 ok, 2 bad input, 1 internal error). No algorithm lives here.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <iostream>

#include <nlohmann/json.hpp>

#include <cmath>
#include <csignal>

#include "estimate/accuracy.h"
#include "output/ply_reader.h"
#include "pipeline/render_job.h"
#include "util/error.h"
#include "pipeline/scene_inspection.h"
#include "run_display.h"
#include "util/progress.h"

namespace {

// The one piece of global state: a signal handler can reach nothing else. Set by the first
// SIGINT/SIGTERM; the render stops after the frame in progress. The handler resets itself, so a
// second signal stops the process at once (every file on disk is still complete: they are
// written atomically, and --resume removes the temporary ones).
volatile std::sig_atomic_t gStopSignal = 0;

extern "C" void requestStop(int signal) { gStopSignal = signal; }

void installStopHandlers() {
    struct sigaction action {};
    action.sa_handler = requestStop;
    action.sa_flags = SA_RESETHAND;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

constexpr int kExitBadInput = 2;
constexpr int kExitInternal = 1;

// Runs a subcommand's work; bad input becomes one line and exit 2, anything else exit 1.
template <typename Work>
int exitCodeOf(Work&& work) {
    try {
        return work();
    } catch (const qsgi::InputError& e) {
        std::fprintf(stderr, "qsgi: error: %s\n", e.what());
        return kExitBadInput;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "qsgi: internal error: %s\n", e.what());
        return kExitInternal;
    }
}

struct CliOptions {
    std::string config, animation, estimator, detpIndex, detpBoundary, frames, out, sampler;
    // Unset options leave the config's (or the default) value alone.
    std::optional<int64_t> photons, seed, threads, width, height, spp, camera;
    std::optional<double> exposure, radius, fps;
    std::optional<int64_t> k, qmcBounces;
    bool noRayCache = false, noSortQueries = false, fullRecompute = false, alwaysUpdate = false, noEnvelope = false, noAim = false, resume = false;
    bool quiet = false, verbose = false, png = false, noExr = false, exrHalf = false, gltfOut = false;
};

// Later sources override earlier ones: defaults, then --config, then explicit options.
qsgi::RenderSettings settingsFrom(const CliOptions& o, const std::string& scene) {
    qsgi::RenderSettings s;
    if (!o.config.empty()) qsgi::applyConfigFile(o.config, s);
    if (!scene.empty()) s.scenePath = scene;
    if (!o.animation.empty()) s.animationPath = o.animation;
    if (o.fps) s.fps = qsgi::checkedFps(*o.fps, "command line", "--fps");
    if (!o.estimator.empty()) s.estimator.kind = qsgi::parseEstimator(o.estimator, "command line");
    if (!o.detpIndex.empty()) s.estimator.detpIndex = qsgi::parseDetpIndex(o.detpIndex, "command line");
    if (!o.detpBoundary.empty()) s.estimator.boundary = qsgi::parseDetpBoundary(o.detpBoundary, "command line");
    if (o.radius) {
        s.estimator.radius = float(*o.radius);
        s.radiusGiven = true;
    }
    const std::string cli = "command line";
    if (o.k) s.estimator.k = int(qsgi::checkedInteger(*o.k, 1, qsgi::kMaxK, cli, "--k"));
    if (o.noRayCache) s.estimator.useIndex = false;
    if (o.noSortQueries) s.estimator.sortQueries = false;
    if (o.fullRecompute) s.fullRecompute = true;
    if (o.alwaysUpdate) s.alwaysUpdate = true;
    if (o.noEnvelope) s.useEnvelope = false;
    if (o.noAim) s.aimEmission = false;
    if (!o.sampler.empty()) s.sampling.kind = qsgi::parseSampler(o.sampler, cli);
    if (o.qmcBounces) {
        s.sampling.qmcBounces = qsgi::checkedQmcBounces(*o.qmcBounces, cli, "--qmc-bounces");
        s.qmcBouncesGiven = true;
    }
    if (o.resume) s.resume = true;
    if (!o.frames.empty()) {
        s.frames = qsgi::parseFrameRange(o.frames, cli);
        s.framesSource = cli;
    }
    if (!o.out.empty()) s.outDir = o.out;
    if (o.photons) s.photons = qsgi::checkedPhotons(*o.photons, cli, "--photons");
    if (o.seed) s.seed = uint64_t(qsgi::checkedInteger(*o.seed, 0, qsgi::kMaxSeed, cli, "--seed"));
    if (o.threads) s.threads = int(qsgi::checkedInteger(*o.threads, 0, qsgi::kMaxThreads, cli, "--threads", " (0: all cores)"));
    if (o.width) s.width = int(qsgi::checkedInteger(*o.width, 1, qsgi::kMaxImageSide, cli, "--width"));
    if (o.height) s.height = int(qsgi::checkedInteger(*o.height, 1, qsgi::kMaxImageSide, cli, "--height"));
    if (o.spp) s.samplesPerPixel = int(qsgi::checkedInteger(*o.spp, 1, qsgi::kMaxSamplesPerPixel, cli, "--spp"));
    if (o.camera) s.cameraIndex = int(qsgi::checkedInteger(*o.camera, 0, INT32_MAX, cli, "--camera"));
    if (o.exposure) s.exposure = float(*o.exposure);
    if (o.png) s.writePng = true;
    if (o.gltfOut) s.writeGltf = true;
    if (o.noExr) s.writeExr = false;
    if (o.exrHalf) s.exrHalf = true;
    s.quiet = o.quiet;
    return s;
}

// `qsgi compare`: reads both PLYs and prints the accuracy report, overall and by edge region.
int runCompare(const std::string& a, const std::string& b, std::optional<double> radiusOption, bool json) {
    const qsgi::VertexRadiosityPly solution = qsgi::readVertexRadiosityPly(a);
    const qsgi::VertexRadiosityPly reference = qsgi::readVertexRadiosityPly(b);
    if (solution.positions.size() != reference.positions.size())
        throw qsgi::InputError(a, "", "has " + std::to_string(solution.positions.size()) + " vertices but " + b + " has " +
                                          std::to_string(reference.positions.size()) + ": not the same scene");
    if (radiusOption && (!(*radiusOption > 0) || !std::isfinite(*radiusOption)))
        throw qsgi::InputError("command line", "--radius", "must be a positive distance (scene units)");
    // Default: qsgi's own default radius, over the reference's vertices.
    qsgi::Bounds3f bounds;
    for (const qsgi::Vec3f& p : reference.positions) bounds.extend(p);
    const float radius = radiusOption ? float(*radiusOption) : qsgi::defaultRadius(bounds);
    const qsgi::AccuracyReport r = qsgi::compareSolutions(reference.positions, reference.normals, reference.triangles,
                                                          solution.radiosity, reference.radiosity, radius);
    const std::pair<const char*, const qsgi::ErrorStats*> rows[] = {
        {"all", &r.all}, {"edge", &r.edge}, {"near_edge", &r.nearEdge}, {"interior", &r.interior}};
    if (json) {
        nlohmann::json j{{"solution", a}, {"reference", b}, {"radius", radius}};
        for (const auto& [name, s] : rows)
            j[name] = {{"vertices", s->vertices}, {"relative_rms", s->relativeRms}, {"relative_bias", s->relativeBias}};
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
    }
    std::printf("%-34s %10s %14s %14s\n", "vertices", "count", "relative RMS", "relative bias");
    const std::string nearLabel = "within " + std::to_string(radius).substr(0, 6) + " of an edge";
    const char* labels[] = {"all", "on an edge (border, crease > 45°)", nearLabel.c_str(), "interior"};
    for (size_t i = 0; i < 4; ++i)
        std::printf("%-34s %10zu %14.5f %+14.5f\n", labels[i], rows[i].second->vertices, rows[i].second->relativeRms,
                    rows[i].second->relativeBias);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"qsgi — global illumination at mesh vertices for animations of quasi-static scenes"};
    app.set_version_flag("--version", std::string("qsgi ") + QSGI_VERSION);
    app.require_subcommand(1);

    CliOptions o;
    std::string scene;
    CLI::App* render = app.add_subcommand("render", "render every frame of a scene's animation to vertex-radiosity PLYs");
    render->add_option("SCENE", scene, "glTF 2.0 scene (.gltf or .glb); may come from --config instead");
    render->add_option("--config", o.config, "JSON config with the same keys (configs/default.json); options override it");
    render->add_option("--animation", o.animation,
                       "qsgi-animation transform file (JSON), or gltf (every animation in the scene file at once) or "
                       "gltf:N (its animation N)");
    render->add_option("--fps", o.fps, "frames per second at which a glTF animation is sampled (default 24)");
    render->add_option("--estimator", o.estimator, "density estimator: detp, photon-map or impact-count (default)");
    render->add_option("--radius", o.radius, "DETP disc / photon-map search radius, scene units (default 1.5 % of the scene diagonal)");
    render->add_option("--k", o.k, "photon map: nearest impacts per vertex (default 50)");
    render->add_option("--detp-index", o.detpIndex, "DETP index: embree (exact, default) or flann (approximate candidates)");
    render->add_option("--detp-boundary", o.detpBoundary,
                       "where discs meet other geometry: clip (default: reachable cells only, no leaks), linear (clip "
                       "plus a first-order fit at edges) or paper (the published rule; the textbook photon map)");
    render->add_flag("--no-ray-cache", o.noRayCache, "density estimation without any spatial index (brute force)");
    render->add_flag("--no-sort-queries", o.noSortQueries, "queries in input order instead of Morton order");
    render->add_flag("--full-recompute", o.fullRecompute,
                     "compute every frame from scratch instead of updating the previous one (same bytes, slower)");
    render->add_flag("--always-update", o.alwaysUpdate,
                     "update every frame after the first incrementally, even one whose change would cost more to update "
                     "than to recompute (same bytes; for measuring the update)");
    render->add_flag("--no-envelope", o.noEnvelope,
                     "track every light path instead of only those that meet the moving geometry's envelope (same "
                     "bytes, more memory and work per frame)");
    render->add_flag("--no-aim", o.noAim,
                     "emit photons in every direction a light shines, not only toward the scene (projection maps "
                     "off; the same estimate in expectation, more photons wasted)");
    render->add_option("--photons", o.photons, "photons traced per frame (default 1000000)");
    render->add_option("--sampler", o.sampler,
                       "where photons' numbers come from: sobol (scrambled Sobol points, stratified; default) or random "
                       "(hashed, independent: the paper's)");
    render->add_option("--qmc-bounces", o.qmcBounces,
                       "sobol: scatterings whose survival and direction are Sobol coordinates too, 0..max_bounces "
                       "(default 2; later ones are hashed)");
    render->add_option("--seed", o.seed, "random seed (default 1); same seed, same bytes");
    render->add_option("--threads", o.threads, "worker threads, 0 = all cores (default 0)");
    render->add_option("--frames", o.frames, "frames A:B, inclusive at both ends (default: all)");
    render->add_option("--out", o.out, "output folder (default out)");
    render->add_flag("--resume", o.resume,
                     "continue the output folder after its last complete frame (same inputs and settings only; "
                     "threads and --full-recompute may differ)");
    render->add_option("--width", o.width, "image width in pixels (default 640)");
    render->add_option("--height", o.height, "image height in pixels (default 480)");
    render->add_option("--spp", o.spp, "jittered primary rays per pixel (default 1: the pixel centre)");
    render->add_option("--camera", o.camera, "use the glTF camera with this index (default: the first camera node)");
    render->add_flag("--no-exr", o.noExr, "do not write frame_NNNN.exr");
    render->add_flag("--exr-half", o.exrHalf, "write EXRs as half floats instead of float");
    render->add_flag("--png", o.png, "also write an 8-bit sRGB preview frame_NNNN.png");
    render->add_flag("--gltf-out", o.gltfOut,
                     "also write frame_NNNN.glb: the posed geometry with COLOR_0 = radiosity/pi on an unlit material "
                     "(irradiance in _IRRADIANCE), for glTF viewers");
    render->add_option("--exposure", o.exposure, "PNG exposure multiplier (default: automatic, fixed at the first frame)");
    render->add_flag("--quiet", o.quiet, "print nothing but errors");
    render->add_flag("--verbose", o.verbose, "print per-frame timings");

    std::string compareA, compareB;
    std::optional<double> compareRadius;
    bool compareJson = false;
    CLI::App* compare = app.add_subcommand("compare", "accuracy of one frame_NNNN.ply against a reference PLY of the same scene");
    compare->add_option("PLY", compareA, "the solution to judge")->required();
    compare->add_option("REFERENCE", compareB, "the reference (e.g. the same estimator at many more photons)")->required();
    compare->add_option("--radius,--border", compareRadius,
                        "the 'near an edge' distance, scene units (default 1.5 % of the scene diagonal, qsgi's default radius)");
    compare->add_flag("--json", compareJson, "print JSON instead of a table");

    CliOptions io;
    std::string inspectScene;
    bool inspectJson = false;
    CLI::App* inspect = app.add_subcommand(
        "inspect", "what a render of this scene would see: meshes, materials, lights, cameras, what moves, the radius, warnings");
    inspect->add_option("SCENE", inspectScene, "glTF 2.0 scene (.gltf or .glb); may come from --config instead");
    inspect->add_option("--animation", io.animation, "as for render: a transform file, gltf or gltf:N");
    inspect->add_option("--config", io.config, "as for render: its lights, radius, frames and camera are included");
    inspect->add_option("--fps", io.fps, "as for render: frames per second of a glTF animation (default 24)");
    inspect->add_flag("--json", inspectJson, "print JSON instead of text");

    try {
        app.parse(argc, argv);
    } catch (const CLI::Success& e) {  // --help, --version
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // One line, like every other bad input (CLI11's own report takes two).
        std::fprintf(stderr, "qsgi: error: command line: %s (see qsgi --help)\n", e.what());
        return kExitBadInput;
    }

    if (compare->parsed()) return exitCodeOf([&] { return runCompare(compareA, compareB, compareRadius, compareJson); });

    if (inspect->parsed())
        return exitCodeOf([&] {
            qsgi::Warnings warnings;
            const qsgi::RenderJob job(settingsFrom(io, inspectScene), warnings);
            const nlohmann::json report = qsgi::inspectRender(job, warnings);
            std::fputs(inspectJson ? (report.dump(2) + "\n").c_str() : qsgi::inspectionText(report).c_str(), stdout);
            return 0;
        });

    return exitCodeOf([&] {
        // Before loading, so that a signal at any moment leaves through the same door.
        installStopHandlers();
        qsgi::Warnings warnings;
        qsgi::RenderJob job(settingsFrom(o, scene), warnings);
        if (!o.quiet)
            for (const auto& w : warnings.messages) std::fprintf(stderr, "qsgi: warning: %s\n", w.c_str());
        RunDisplay display(!o.quiet && qsgi::stderrIsTerminal());
        const qsgi::RunOutcome outcome = job.run(
            [&](const qsgi::FrameReport& r) {
                // Lights far from the geometry waste photons; say so once, with the number.
                if (r.index == 0 && r.missedFraction > 0.5 && !o.quiet) {
                    display.clearLine();
                    std::fprintf(stderr, "qsgi: warning: %.0f%% of the photons hit no geometry; the estimate rests on the rest "
                                 "(move lights closer or add photons)\n", 100 * r.missedFraction);
                }
                if (o.verbose) {
                    display.clearLine();
                    std::fprintf(stderr, "qsgi: frame %d (%d/%d) %.3f s\n", r.frame, r.index + 1, r.count, r.seconds);
                }
                display.frameDone(r);
            },
            [] { return gStopSignal != 0; }, [&](const qsgi::StageReport& r) { display.stage(r); });
        display.clearLine();
        const std::string& out = job.outputFolder();
        if (outcome.interrupted) {
            std::fprintf(stderr, "qsgi: stopped by %s after frame %d; every frame before %d is complete in %s (add --resume "
                         "to continue)\n", gStopSignal == SIGINT ? "SIGINT" : "SIGTERM", outcome.nextFrame - 1,
                         outcome.nextFrame, out.c_str());
            return 128 + int(gStopSignal);
        }
        if (o.resume && !o.quiet && outcome.framesWritten == 0)
            std::fprintf(stderr, "qsgi: every frame is already complete in %s\n", out.c_str());
        else if (!o.quiet)
            std::fprintf(stderr, "qsgi: %s\n", display.summary(out).c_str());
        return 0;
    });
}
