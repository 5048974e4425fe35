// qsgi: the command-line host. Parses options, configures a RenderJob, reports progress and maps
// errors to exit codes (0 ok, 2 bad input, 1 internal error). No algorithm lives here.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <iostream>

#include "pipeline/render_job.h"
#include "util/error.h"
#include "util/progress.h"

namespace {

constexpr int kExitBadInput = 2;
constexpr int kExitInternal = 1;

struct CliOptions {
    std::string config, animation, estimator, detpIndex, frames, out;
    // Unset options leave the config's (or the default) value alone.
    std::optional<int64_t> photons, seed, threads, width, height, spp, camera;
    std::optional<double> exposure, radius;
    std::optional<int64_t> k;
    bool noRayCache = false, noSortQueries = false;
    bool quiet = false, verbose = false, png = false, noExr = false, exrHalf = false;
};

// Later sources override earlier ones: defaults, then --config, then explicit options.
qsgi::RenderSettings settingsFrom(const CliOptions& o, const std::string& scene) {
    qsgi::RenderSettings s;
    if (!o.config.empty()) qsgi::applyConfigFile(o.config, s);
    if (!scene.empty()) s.scenePath = scene;
    if (!o.animation.empty()) s.animationPath = o.animation;
    if (!o.estimator.empty()) s.estimator.kind = qsgi::parseEstimator(o.estimator, "command line");
    if (!o.detpIndex.empty()) s.estimator.detpIndex = qsgi::parseDetpIndex(o.detpIndex, "command line");
    if (o.radius) {
        s.estimator.radius = float(*o.radius);
        s.radiusGiven = true;
    }
    if (o.k) s.estimator.k = int(std::clamp<int64_t>(*o.k, -1, 1 << 24));
    if (o.noRayCache) s.estimator.useIndex = false;
    if (o.noSortQueries) s.estimator.sortQueries = false;
    if (!o.frames.empty()) s.frames = qsgi::parseFrameRange(o.frames, "command line");
    if (!o.out.empty()) s.outDir = o.out;
    if (o.photons) {
        if (*o.photons <= 0) throw qsgi::InputError("command line", "--photons", "must be a positive integer");
        s.photons = uint64_t(*o.photons);
    }
    if (o.seed) {
        if (*o.seed < 0) throw qsgi::InputError("command line", "--seed", "must be a non-negative integer");
        s.seed = uint64_t(*o.seed);
    }
    if (o.threads) {
        if (*o.threads < 0) throw qsgi::InputError("command line", "--threads", "must be a non-negative integer (0: all cores)");
        s.threads = int(std::min<int64_t>(*o.threads, 1024));
    }
    // Out-of-range sizes are clamped into int range here and rejected by validateSettings.
    auto clampToInt = [](int64_t v) { return int(std::clamp<int64_t>(v, -1, 1 << 24)); };
    if (o.width) s.width = clampToInt(*o.width);
    if (o.height) s.height = clampToInt(*o.height);
    if (o.spp) s.samplesPerPixel = clampToInt(*o.spp);
    if (o.camera) s.cameraIndex = clampToInt(*o.camera);
    if (o.exposure) s.exposure = float(*o.exposure);
    if (o.png) s.writePng = true;
    if (o.noExr) s.writeExr = false;
    if (o.exrHalf) s.exrHalf = true;
    s.quiet = o.quiet;
    s.progress = !o.quiet && qsgi::stderrIsTerminal();
    return s;
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
    render->add_option("--animation", o.animation, "qsgi-animation transform file (JSON)");
    render->add_option("--estimator", o.estimator, "density estimator: detp, photon-map or impact-count (default)");
    render->add_option("--radius", o.radius, "DETP disc / photon-map search radius, scene units (default 1.5 % of the scene diagonal)");
    render->add_option("--k", o.k, "photon map: nearest impacts per vertex (default 50)");
    render->add_option("--detp-index", o.detpIndex, "DETP index: embree (exact, default) or flann (approximate candidates)");
    render->add_flag("--no-ray-cache", o.noRayCache, "density estimation without any spatial index (brute force)");
    render->add_flag("--no-sort-queries", o.noSortQueries, "queries in input order instead of Morton order");
    render->add_option("--photons", o.photons, "photons traced per frame (default 1000000)");
    render->add_option("--seed", o.seed, "random seed (default 1); same seed, same bytes");
    render->add_option("--threads", o.threads, "worker threads, 0 = all cores (default 0)");
    render->add_option("--frames", o.frames, "frames A:B, inclusive at both ends (default: all)");
    render->add_option("--out", o.out, "output folder (default out)");
    render->add_option("--width", o.width, "image width in pixels (default 640)");
    render->add_option("--height", o.height, "image height in pixels (default 480)");
    render->add_option("--spp", o.spp, "jittered primary rays per pixel (default 1: the pixel centre)");
    render->add_option("--camera", o.camera, "use the glTF camera with this index (default: the first camera node)");
    render->add_flag("--no-exr", o.noExr, "do not write frame_NNNN.exr");
    render->add_flag("--exr-half", o.exrHalf, "write EXRs as half floats instead of float");
    render->add_flag("--png", o.png, "also write an 8-bit sRGB preview frame_NNNN.png");
    render->add_option("--exposure", o.exposure, "PNG exposure multiplier (default: automatic, fixed at the first frame)");
    render->add_flag("--quiet", o.quiet, "print nothing but errors");
    render->add_flag("--verbose", o.verbose, "print per-frame timings");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : kExitBadInput;
    }

    try {
        qsgi::Warnings warnings;
        qsgi::RenderJob job(settingsFrom(o, scene), warnings);
        if (!o.quiet)
            for (const auto& w : warnings.messages) std::fprintf(stderr, "qsgi: warning: %s\n", w.c_str());
        job.run([&](const qsgi::FrameReport& r) {
            if (o.verbose) std::fprintf(stderr, "qsgi: frame %d (%d/%d) %.3f s\n", r.frame, r.index + 1, r.count, r.seconds);
        });
        return 0;
    } catch (const qsgi::InputError& e) {
        std::fprintf(stderr, "qsgi: error: %s\n", e.what());
        return kExitBadInput;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "qsgi: internal error: %s\n", e.what());
        return kExitInternal;
    }
}
