#include "output/timing_log.h"

#include <string_view>

#include <nlohmann/json.hpp>

#include <algorithm>

#include "util/error.h"
#include "util/json_file.h"

namespace qsgi {

namespace {
nlohmann::json summary(std::vector<double> v) {
    if (v.empty()) return nullptr;
    std::sort(v.begin(), v.end());
    double sum = 0;
    for (double x : v) sum += x;
    const size_t n = v.size();
    const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    return {{"mean", sum / double(n)}, {"median", median}, {"max", v.back()}};
}
}  // namespace

std::string TimingLog::text() const {
    using nlohmann::json;
    json j;
    j["version"] = QSGI_VERSION;
    j["config"] = config;
    j["config"]["inputs_fingerprint"] = inputsFingerprint;
    j["inputs"] = inputs;
    j["scene"] = {{"file", pathJson(scene)}, {"vertices", vertices}, {"triangles", triangles},
                  {"dynamic_vertices", dynamicVertices}, {"lights", lights},
                  {"degenerate_triangles", degenerateTriangles}, {"animation_diagonal", animationDiagonal},
                  {"input_vertices", inputVertices}, {"back_side_vertices", backSideVertices},
                  {"contact_refinement", contactRefinement},
                  {"fit_samples", fitSamples ? nlohmann::json(fitSamples) : nlohmann::json(nullptr)}};
    // Aimed emission's effect (issue 12), from the run's first frame: the share of the lights'
    // power sent toward the scene, and the photons whose first segment still hit nothing.
    const bool traced = emissionMeasured;
    j["emission"] = {{"emitted_fraction", traced ? json(emittedFraction) : json(nullptr)},
                     {"first_segment_miss_rate",
                      traced ? json(double(photonsMissingScene) / double(std::max<uint64_t>(photons, 1))) : json(nullptr)}};
    j["setup"] = setup;
    std::vector<double> updates, estimates;
    for (size_t i = 1; i < frames.size(); ++i) {
        updates.push_back(frames[i].photonSimulationSeconds);
        estimates.push_back(frames[i].estimationSeconds);
    }
    j["photon_simulation"] = {{"initial_s", frames.empty() ? 0.0 : frames[0].photonSimulationSeconds},
                              {"update_s", summary(updates)}};
    j["density_estimation"] = {{"initial_s", frames.empty() ? 0.0 : frames[0].estimationSeconds},
                               {"frame_s", summary(estimates)}};
    // In frame order, however the frames were computed (a re-render of a range, a resumed run).
    std::vector<const FrameTiming*> ordered;
    for (const FrameTiming& f : frames) ordered.push_back(&f);
    std::stable_sort(ordered.begin(), ordered.end(), [](const FrameTiming* a, const FrameTiming* b) { return a->frame < b->frame; });
    json list = json::array();
    for (const FrameTiming* frame : ordered) {
        const FrameTiming& f = *frame;
        json entry;
        forEachTimingField(f, [&](const char* name, const auto& value) { entry[name] = value; });
        json files = json::array();
        for (const FileRecord& file : f.files) files.push_back({{"name", file.name}, {"bytes", file.bytes}, {"xxh3", file.xxh3}});
        entry["files"] = files;
        list.push_back(entry);
    }
    j["frames"] = list;
    // Every name in it is UTF-8 (pathJson), but a string the log only shows (an option's text)
    // must not stop a render: such bytes are shown as U+FFFD.
    return j.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

EarlierRun readTimingLog(const std::filesystem::path& path) {
    const nlohmann::json j = readJsonFile(path.string());
    EarlierRun run;
    try {
        run.inputsFingerprint = j.at("config").at("inputs_fingerprint").get<std::string>();
        if (j.contains("inputs")) run.inputs = j.at("inputs");
        for (const nlohmann::json& entry : j.at("frames")) {
            FrameTiming f;
            // A counter that a log of an earlier version did not have yet (fit_bytes) reads as its
            // default: --resume accepts a folder of the same inputs whichever version wrote it.
            forEachTimingField(f, [&](const char* name, auto& value) {
                if (std::string_view(name) == "frame" || entry.contains(name)) entry.at(name).get_to(value);
            });
            if (entry.contains("files"))
                for (const nlohmann::json& file : entry.at("files"))
                    f.files.push_back(FileRecord{file.at("name").get<std::string>(), file.at("bytes").get<uint64_t>(),
                                                 file.at("xxh3").get<std::string>()});
            run.frames.push_back(f);
        }
    } catch (const nlohmann::json::exception& e) {
        throw InputError(path.string(), "", std::string("is not a timing log of this qsgi version (") + e.what() + ")");
    }
    return run;
}

}  // namespace qsgi
