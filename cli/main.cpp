// qsgi: the command-line host. Parses options, configures a RenderJob, reports progress and maps
// errors to exit codes (0 ok, 2 bad input, 1 internal error). No algorithm lives here.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <optional>
#include <utility>
#include <iostream>

#include <nlohmann/json.hpp>

#include <cmath>
#include <csignal>

#include "estimate/accuracy.h"
#include "estimate/surface_accuracy.h"
#include "output/ply_reader.h"
#include "pipeline/render_job.h"
#include "pipeline/render_options.h"
#include "util/error.h"
#include "util/input_file.h"
#include "util/nearest_name.h"
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
    // SA_RESTART: a write or fsync the signal lands in goes on (the run stops after the frame).
    action.sa_flags = SA_RESETHAND | SA_RESTART;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

constexpr int kExitBadInput = 2;
constexpr int kExitInternal = 1;
constexpr int kExitEnvironment = 74;  // sysexits' EX_IOERR: the disk failed (full, I/O error)
constexpr int kExitBusy = 75;         // sysexits' EX_TEMPFAIL: another run holds the folder; retry later

// What a subcommand's work ended with: its exit code and, when it failed, the one line saying why.
struct WorkOutcome {
    int exitCode = 0;
    std::string error;  // "qsgi: error: ...", empty when the work succeeded
};

// Runs a subcommand's work; bad input becomes one line and exit 2, a failing disk 74, a folder
// another run holds 75, anything else exit 1.
template <typename Work>
WorkOutcome outcomeOf(Work&& work) {
    try {
        return {work(), ""};
    } catch (const qsgi::InputError& e) {
        return {kExitBadInput, std::string("qsgi: error: ") + e.what()};
    } catch (const qsgi::EnvironmentError& e) {
        return {kExitEnvironment, std::string("qsgi: error: ") + e.what()};
    } catch (const qsgi::FolderBusyError& e) {
        return {kExitBusy, std::string("qsgi: error: ") + e.what()};
    } catch (const std::exception& e) {
        return {kExitInternal, std::string("qsgi: internal error: ") + e.what()};
    }
}

// outcomeOf, its line on stderr.
template <typename Work>
int exitCodeOf(Work&& work) {
    const WorkOutcome outcome = outcomeOf(std::forward<Work>(work));
    if (!outcome.error.empty()) std::fprintf(stderr, "%s\n", outcome.error.c_str());
    return outcome.exitCode;
}

// A render's options on the command line, made from the one table (lib/pipeline/render_options.cpp):
// each is kept as the text given and applied after --config by the rules a config's value meets.
using BoundOptions = std::vector<std::pair<const qsgi::RenderOption*, CLI::Option*>>;

std::string commandLineHelp(const qsgi::RenderOption& o) {
    std::string help = o.help;
    if (*o.defaultText && o.type != qsgi::OptionType::Boolean) help += " (default: " + std::string(o.defaultText) + ")";
    return help;
}

// Adds the options with a flag (all of them, or those named in `only`) to `command`.
BoundOptions addRenderOptions(CLI::App* command, const std::vector<std::string>& only = {}) {
    BoundOptions bound;
    for (const qsgi::RenderOption& o : qsgi::renderOptions()) {
        if (!o.flag || (!only.empty() && std::find(only.begin(), only.end(), o.flag) == only.end())) continue;
        CLI::Option* option = o.type == qsgi::OptionType::Boolean ? command->add_flag(std::string(o.flag))
                                                                  : command->add_option(std::string(o.flag));
        option->description(commandLineHelp(o));
        option->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);  // as most tools: the last one given wins
        std::string metavar = o.metavar;
        for (const std::string& choice : o.choices) metavar += (metavar.empty() ? "" : "|") + choice;
        if (!metavar.empty()) option->type_name(metavar);
        bound.emplace_back(&o, option);
    }
    return bound;
}

// Later sources override earlier ones: the defaults, then --config, then the other options.
qsgi::RenderSettings settingsFrom(const BoundOptions& bound) {
    qsgi::RenderSettings s;
    for (const auto& [o, option] : bound)
        if (std::string(o->flag) == "--config" && option->count()) qsgi::applyConfigFile(option->as<std::string>(), s);
    for (const auto& [o, option] : bound)
        if (o->set && option->count())
            qsgi::applyCommandLineOption(*o, o->type == qsgi::OptionType::Boolean ? "" : option->as<std::string>(), s);
    return s;
}

// One line for a command line CLI11 cannot parse. A flag the subcommand does not know is named
// with the nearest one it does (as a config's unknown key is); anything else keeps CLI11's words.
std::string commandLineError(const CLI::App& app, int argc, char** argv, const CLI::ParseError& error) {
    const auto all = [](const CLI::App*) { return true; };
    std::vector<std::string> subcommands;
    for (const CLI::App* sub : app.get_subcommands(all)) subcommands.push_back(sub->get_name());
    const CLI::App* command = nullptr;
    for (int i = 1; i < argc && !command; ++i)
        for (const CLI::App* sub : app.get_subcommands(all))
            if (sub->get_name() == argv[i]) command = sub;
    std::string list;
    for (const std::string& name : subcommands) list += (list.empty() ? "" : ", ") + name;
    if (!command) {
        // No subcommand: the first word that is not a flag is a mistyped one.
        for (int i = 1; i < argc; ++i)
            if (argv[i][0] != '-')
                return "unknown subcommand '" + std::string(argv[i]) + "'" + qsgi::didYouMean(argv[i], subcommands) +
                       " (subcommands: " + list + "; see qsgi --help)";
        return std::string(error.what()) + " (subcommands: " + list + "; see qsgi --help)";
    }
    std::vector<std::string> flags;  // the subcommand's own, the candidates for "nearest"
    for (const CLI::Option* option : command->get_options()) {
        for (const std::string& name : option->get_lnames())
            if (name != "help") flags.push_back("--" + name);
        for (const std::string& name : option->get_snames())
            if (name != "h") flags.push_back("-" + name);
    }
    const std::string help = "qsgi " + command->get_name() + " --help";
    for (int i = 1; i < argc; ++i) {
        const std::string word = argv[i];
        if (word == "--") break;
        // A flag: "--name" or "-x" (not a negative number, which is a value).
        if (word.size() < 2 || word[0] != '-' || !(std::isalpha(static_cast<unsigned char>(word[1])) || word[1] == '-')) continue;
        const std::string name = word.substr(0, word.find('='));
        if (name == "--help" || name == "-h" || std::find(flags.begin(), flags.end(), name) != flags.end()) continue;
        // The nearest known flag, always named: a close one as a question, else as the nearest.
        std::string nearest = qsgi::didYouMean(name, flags);
        if (nearest.empty() && !flags.empty()) {
            const auto closest = std::min_element(flags.begin(), flags.end(), [&](const std::string& x, const std::string& y) {
                return qsgi::editDistance(name, x) < qsgi::editDistance(name, y);
            });
            nearest = " (the nearest is " + *closest + ")";
        }
        return "unknown flag " + name + " for qsgi " + command->get_name() + nearest + "; " + help + " lists them";
    }
    return std::string(error.what()) + " (see " + help + ")";
}

// `qsgi compare` against a surface reference: the frame's irradiance interpolated at its points,
// overall and by band (contact, edge, interior), with the reference's noise taken out.
// width: the bands' (--radius; default qsgi's default radius over the frame's vertices).
int runSurfaceCompare(qsgi::InputFile& solutionFile, qsgi::InputFile& referenceFile, std::optional<double> widthOption,
                      bool json) {
    const std::string &a = solutionFile.path(), &b = referenceFile.path();
    const qsgi::VertexRadiosityPly solution = qsgi::readVertexRadiosityPly(solutionFile);
    qsgi::Bounds3f bounds;
    for (const qsgi::Vec3f& p : solution.positions) bounds.extend(p);
    const float width = widthOption ? float(*widthOption) : qsgi::defaultRadius(bounds);
    const qsgi::SurfaceReferencePly reference = qsgi::readSurfaceReferencePly(referenceFile);
    if (solution.irradiance.empty())
        throw qsgi::InputError(a, "header", "has no irradiance_r/g/b: a surface reference scores irradiance");
    qsgi::SurfaceAccuracyReport r;
    try {
        r = qsgi::compareOverSurface(solution.positions, solution.normals, solution.triangles, solution.irradiance,
                                     reference.points, width);
    } catch (const std::invalid_argument& e) {
        throw qsgi::InputError(b, "", std::string(e.what()) + " (the frame: " + a + ")");
    }
    const std::pair<const char*, const qsgi::SurfaceErrorStats*> rows[] = {
        {"all", &r.all}, {"contact", &r.contact}, {"edge", &r.edge}, {"interior", &r.interior}};
    if (json) {
        nlohmann::json j{{"solution", a}, {"reference", b}, {"band_width", width}, {"hidden", r.hidden}};
        for (const auto& [name, s] : rows)
            j[name] = {{"points", s->points}, {"relative_rms", s->relativeRms}, {"relative_bias", s->relativeBias},
                       {"reference_noise", s->referenceNoise}, {"relative_rms_without_noise", s->withoutNoise}};
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
    }
    const std::string w = std::to_string(width).substr(0, 6);
    std::printf("%-44s %8s %13s %14s %12s %14s\n", "surface points (irradiance interpolated)", "count", "relative RMS",
                "relative bias", "ref. noise", "without noise");
    const std::string labels[] = {"all visible (" + std::to_string(r.hidden) + " hidden left out)",
                                  "within " + w + " of another surface", "within " + w + " of an edge", "interior"};
    for (size_t i = 0; i < 4; ++i)
        std::printf("%-44s %8zu %13.5f %+14.5f %12.5f %14.5f\n", labels[i].c_str(), rows[i].second->points, rows[i].second->relativeRms,
                    rows[i].second->relativeBias, rows[i].second->referenceNoise, rows[i].second->withoutNoise);
    return 0;
}

// `qsgi compare`: reads both PLYs and prints the accuracy report, overall and by edge region.
// Each file is opened once: the reference's header says which reader takes it, from the same
// descriptor.
int runCompare(const std::string& a, const std::string& b, std::optional<double> radiusOption, bool json) {
    if (radiusOption && (!(*radiusOption > 0) || !std::isfinite(*radiusOption)))
        throw qsgi::InputError("command line", "--radius", "must be a positive distance (scene units)");
    qsgi::InputFile solutionFile(a, UINT64_MAX, "a PLY file"), referenceFile(b, UINT64_MAX, "a PLY file");
    if (qsgi::plyFirstElement(referenceFile) == "point") return runSurfaceCompare(solutionFile, referenceFile, radiusOption, json);
    const qsgi::VertexRadiosityPly solution = qsgi::readVertexRadiosityPly(solutionFile);
    const qsgi::VertexRadiosityPly reference = qsgi::readVertexRadiosityPly(referenceFile);
    if (solution.positions.size() != reference.positions.size())
        throw qsgi::InputError(a, "", "has " + std::to_string(solution.positions.size()) + " vertices but " + b + " has " +
                                          std::to_string(reference.positions.size()) + ": not the same scene");
    // Default: qsgi's own default radius, over the reference's vertices.
    qsgi::Bounds3f bounds;
    for (const qsgi::Vec3f& p : reference.positions) bounds.extend(p);
    const float radius = radiusOption ? float(*radiusOption) : qsgi::defaultRadius(bounds);
    // A reference of a vertex subset (scripts/reference.py --vertices N) is judged on its subset.
    const std::vector<bool> only(reference.referenced.begin(), reference.referenced.end());
    if (!reference.referenced.empty() && std::count(only.begin(), only.end(), true) == 0)
        throw qsgi::InputError(b, "vertex property 'referenced'", "flags no vertex: nothing to compare");
    const qsgi::AccuracyReport r = qsgi::compareSolutions(reference.positions, reference.normals, reference.triangles,
                                                          solution.radiosity, reference.radiosity, radius, only);
    const std::pair<const char*, const qsgi::ErrorStats*> rows[] = {
        {"all", &r.all}, {"edge", &r.edge}, {"near_edge", &r.nearEdge}, {"interior", &r.interior}, {"contact", &r.contact}};
    if (json) {
        nlohmann::json j{{"solution", a}, {"reference", b}, {"radius", radius}};
        for (const auto& [name, s] : rows)
            j[name] = {{"vertices", s->vertices}, {"relative_rms", s->relativeRms}, {"relative_bias", s->relativeBias}};
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
    }
    std::printf("%-34s %10s %14s %14s\n", "vertices", "count", "relative RMS", "relative bias");
    const std::string nearLabel = "within " + std::to_string(radius).substr(0, 6) + " of an edge";
    const char* labels[] = {"all", "on an edge (border, crease > 45°)", nearLabel.c_str(), "interior",
                            "touching another surface"};
    for (size_t i = 0; i < 5; ++i)
        std::printf("%-34s %10zu %14.5f %+14.5f\n", labels[i], rows[i].second->vertices, rows[i].second->relativeRms,
                    rows[i].second->relativeBias);
    return 0;
}

// What `qsgi inspect` reports for these settings: the scene loaded and checked as a render would.
nlohmann::json inspectionOf(qsgi::RenderSettings settings) {
    qsgi::Warnings warnings;
    const qsgi::RenderJob job(std::move(settings), warnings);
    return qsgi::inspectRender(job, warnings);
}

// `qsgi inspect --scenes LIST`: each listed scene inspected with `settings`, one JSON line each, so
// that a folder of assets (or the glTF-Validator's corpus, scripts/validator_corpus.py) is checked
// without a process start per file. Each line's exit code and error are what the scene alone gives.
int inspectEach(const std::string& listPath, const qsgi::RenderSettings& settings) {
    constexpr uint64_t kMaxListBytes = uint64_t(1) << 26;
    const std::string list = qsgi::readInputFile(listPath, kMaxListBytes, "scene list");
    int refused = 0, otherFailure = 0;
    size_t start = 0;
    while (start < list.size()) {
        size_t end = list.find('\n', start);
        if (end == std::string::npos) end = list.size();
        std::string scene = list.substr(start, end - start);
        start = end + 1;
        if (!scene.empty() && scene.back() == '\r') scene.pop_back();
        if (scene.empty()) continue;
        nlohmann::json report;
        const WorkOutcome outcome = outcomeOf([&] {
            qsgi::RenderSettings own = settings;
            own.scenePath = scene;
            report = inspectionOf(std::move(own));
            return 0;
        });
        const nlohmann::json line = {{"scene", scene}, {"exit", outcome.exitCode}, {"error", outcome.error}, {"report", report}};
        std::printf("%s\n", line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
        std::fflush(stdout);
        if (outcome.exitCode == kExitBadInput) refused = kExitBadInput;
        else if (outcome.exitCode != 0 && otherFailure == 0) otherFailure = outcome.exitCode;
    }
    return otherFailure ? otherFailure : refused;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"qsgi — global illumination at mesh vertices for animations of quasi-static scenes"};
    app.set_version_flag("--version", std::string("qsgi ") + QSGI_VERSION);
    app.require_subcommand(1);
    app.footer("Each subcommand has its own help: qsgi render --help, qsgi inspect --help, qsgi compare --help, "
               "qsgi options --help. Every option and config key: docs/command-line.md.");

    CLI::App* render = app.add_subcommand("render", "render every frame of a scene's animation to vertex-radiosity PLYs");
    const BoundOptions renderOptions = addRenderOptions(render);

    std::string compareA, compareB;
    std::optional<double> compareRadius;
    bool compareJson = false;
    CLI::App* compare = app.add_subcommand("compare", "accuracy of one frame_NNNN.ply against a reference PLY of the same scene: its vertices, or "
                                                   "points on its surface (reference.py --surface)");
    compare->add_option("PLY", compareA, "the solution to judge")->required();
    compare->add_option("REFERENCE", compareB, "the reference (e.g. the same estimator at many more photons)")->required();
    compare->add_option("--radius,--border", compareRadius,
                        "the 'near an edge' distance, and against a surface reference also the 'near another surface' one, scene units "
                        "(default 1.5 % of the scene diagonal, qsgi's default radius)");
    compare->add_flag("--json", compareJson, "print JSON instead of a table");

    CLI::App* inspect = app.add_subcommand(
        "inspect", "what a render with these options would see and do: meshes, materials, lights, cameras, what moves, "
                   "the radius, the options set, the output folder's state, warnings");
    // Every render option, so that a render's command line can be checked by changing the verb.
    const BoundOptions inspectOptions = addRenderOptions(inspect);
    bool inspectJson = false;
    inspect->add_flag("--json", inspectJson, "print JSON instead of text");
    std::string inspectScenes;
    CLI::Option* scenesOption = inspect->add_option(
        "--scenes", inspectScenes,
        "inspect each scene this file lists (one path a line) with the other options, in one process: one JSON line "
        "each, {scene, exit, error, report}, with the exit code and error line `qsgi inspect SCENE --json` would give "
        "alone; exits 2 if any scene is refused");
    scenesOption->type_name("LIST");
    for (const auto& [o, option] : inspectOptions)
        if (o->key && std::string(o->key) == "scene") scenesOption->excludes(option);

    CLI::App* options = app.add_subcommand("options", "every render option: its flag, config key, default and meaning");
    bool optionsMarkdown = false;
    options->add_flag("--markdown", optionsMarkdown, "print the table of docs/command-line.md instead of JSON");

    try {
        app.parse(argc, argv);
    } catch (const CLI::Success& e) {  // --help, --version
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // One line, like every other bad input (CLI11's own report takes two).
        std::fprintf(stderr, "qsgi: error: command line: %s\n", commandLineError(app, argc, argv, e).c_str());
        return kExitBadInput;
    }

    if (compare->parsed()) return exitCodeOf([&] { return runCompare(compareA, compareB, compareRadius, compareJson); });

    if (options->parsed()) {
        if (optionsMarkdown) std::fputs(qsgi::optionsMarkdownTable().c_str(), stdout);
        else std::printf("%s\n", qsgi::optionsDescription().dump(2).c_str());
        return 0;
    }

    if (inspect->parsed() && !inspectScenes.empty())
        return exitCodeOf([&] { return inspectEach(inspectScenes, settingsFrom(inspectOptions)); });
    if (inspect->parsed())
        return exitCodeOf([&] {
            const nlohmann::json report = inspectionOf(settingsFrom(inspectOptions));
            // Names are UTF-8 or pathJson's objects; bytes a message quotes are shown as U+FFFD.
            const std::string text =
                inspectJson ? report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n" : qsgi::inspectionText(report);
            std::fputs(text.c_str(), stdout);
            return 0;
        });

    return exitCodeOf([&] {
        // Before loading, so that a signal at any moment leaves through the same door.
        installStopHandlers();
        qsgi::Warnings warnings;
        qsgi::RenderJob job(settingsFrom(renderOptions), warnings);
        job.refuseIfUnlit();  // before any warning, so that bad input is one line
        const qsgi::RenderSettings& o = job.settings();
        if (!o.quiet)
            for (const auto& w : warnings.messages) std::fprintf(stderr, "qsgi: warning: %s\n", w.c_str());
        RunDisplay display(!o.quiet && qsgi::stderrIsTerminal());
        qsgi::RunObserver observer;
        observer.onWarning = [&](const std::string& w) {
            if (!o.quiet) display.message("qsgi: warning: " + w);
        };
        observer.stopRequested = [] { return gStopSignal != 0; };
        observer.onStage = [&](const qsgi::StageReport& r) { display.stage(r); };
        observer.onFrame = [&](const qsgi::FrameReport& r) {
            // Lights far from the geometry waste photons; say so once, with the number.
            char text[256];
            if (r.index == 0 && r.missedFraction > 0.5 && !o.quiet) {
                std::snprintf(text, sizeof text, "qsgi: warning: %.0f%% of the photons hit no geometry; the estimate "
                              "rests on the rest (move lights closer or add photons; a sky's photons cross the whole disc around "
                              "the scene's bounds)", 100 * r.missedFraction);
                display.message(text);
            }
            if (o.verbose) {
                std::snprintf(text, sizeof text, "qsgi: frame %d (%d/%d) %.3f s", r.frame, r.index + 1, r.count, r.seconds);
                display.message(text);
            }
            display.frameDone(r);
        };
        const qsgi::RunOutcome outcome = job.run(observer);
        display.finish();
        const std::string& out = job.outputFolder();
        if (outcome.interrupted) {
            std::fprintf(stderr, "qsgi: stopped by %s after frame %d; every frame before %d is complete in %s (add --resume "
                         "to continue)\n", gStopSignal == SIGINT ? "SIGINT" : "SIGTERM", outcome.nextFrame - 1,
                         outcome.nextFrame, out.c_str());
            return 128 + int(gStopSignal);
        }
        if (o.resume && !o.quiet && outcome.framesWritten == 0 && outcome.framesRemoved > 0)
            std::fprintf(stderr, "qsgi: every frame asked for is already complete in %s; %d damaged frame%s outside them %s removed\n",
                         out.c_str(), outcome.framesRemoved, outcome.framesRemoved == 1 ? "" : "s",
                         outcome.framesRemoved == 1 ? "was" : "were");
        else if (o.resume && !o.quiet && outcome.framesWritten == 0)
            std::fprintf(stderr, "qsgi: every frame is already complete in %s\n", out.c_str());
        else if (!o.quiet)
            std::fprintf(stderr, "qsgi: %s\n", display.summary(out, outcome).c_str());
        for (const qsgi::WholeRunReport& file : outcome.wholeRunFiles)
            if (!o.quiet)
                std::fprintf(stderr, "qsgi: wrote %s/%s: %s (%.2f s to assemble and write)\n", out.c_str(), file.name.c_str(),
                             file.sizes.c_str(), file.seconds);
        if (!o.quiet && outcome.filesReplaced > 0)
            std::fprintf(stderr, "qsgi: --overwrite: unlinked %d files of another run from %s before rendering\n",
                         outcome.filesReplaced, out.c_str());
        if (!o.quiet && !job.unplayedAnimationsNote().empty())
            std::fprintf(stderr, "qsgi: note: %s: %s\n", o.scenePath.c_str(), job.unplayedAnimationsNote().c_str());
        return 0;
    });
}
