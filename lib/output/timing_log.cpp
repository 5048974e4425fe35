#include "output/timing_log.h"

#include <nlohmann/json.hpp>

#include <algorithm>

#include "output/atomic_file.h"

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

void TimingLog::write(const std::filesystem::path& path) const {
    using nlohmann::json;
    json j;
    j["version"] = QSGI_VERSION;
    const bool hasRadius = estimator != "impact-count";
    j["config"] = {{"estimator", estimator}, {"photons", photons},
                   {"radius", hasRadius ? nlohmann::json(radius) : nlohmann::json(nullptr)},
                   {"k", estimator == "photon-map" ? nlohmann::json(k) : nlohmann::json(nullptr)},
                   {"detp_index", estimator == "detp" ? nlohmann::json(detpIndex) : nlohmann::json(nullptr)},
                   {"detp_boundary", hasRadius ? nlohmann::json(boundary) : nlohmann::json(nullptr)},
                   {"ray_cache", rayCache}, {"sort_queries", sortQueries}, {"full_recompute", fullRecompute}, {"envelope", envelope},
                   {"seed", seed}, {"threads", threads}};
    j["scene"] = {{"file", scene}, {"vertices", vertices}, {"triangles", triangles},
                  {"dynamic_vertices", dynamicVertices}, {"lights", lights},
                  {"degenerate_triangles", degenerateTriangles}};
    std::vector<double> updates, estimates;
    for (size_t i = 1; i < frames.size(); ++i) {
        updates.push_back(frames[i].photonSimulationSeconds);
        estimates.push_back(frames[i].estimationSeconds);
    }
    j["photon_simulation"] = {{"initial_s", frames.empty() ? 0.0 : frames[0].photonSimulationSeconds},
                              {"update_s", summary(updates)}};
    j["density_estimation"] = {{"initial_s", frames.empty() ? 0.0 : frames[0].estimationSeconds},
                               {"frame_s", summary(estimates)}};
    json list = json::array();
    for (const FrameTiming& f : frames)
        list.push_back({{"frame", f.frame}, {"from_scratch", f.fromScratch}, {"photon_update_s", f.photonSimulationSeconds},
                        {"find_affected_s", f.findAffectedSeconds}, {"retrace_s", f.retraceSeconds},
                        {"paths_affected_by_impact", f.pathsAffectedByImpact},
                        {"paths_affected_by_blocking", f.pathsAffectedByBlocking}, {"tracked_paths", f.trackedPaths},
                        {"tracked_segments", f.trackedSegments}, {"tracked_bytes", f.trackedBytes},
                        {"recompute_s", f.recomputeSeconds}, {"vertices_recomputed", f.verticesRecomputed},
                        {"estimation_s", f.estimationSeconds}, {"render_s", f.renderSeconds},
                        {"write_s", f.writeSeconds},
                        {"segments", f.segments}, {"photons_missing_scene", f.photonsMissingScene}, {"paths_retraced", f.pathsRetraced},
                        {"segments_removed", f.segmentsRemoved}, {"segments_added", f.segmentsAdded},
                        {"vertices_updated", f.verticesUpdated}, {"disc_regions_s", f.discRegionsSeconds},
                        {"disc_regions_updated", f.discRegionsUpdated}, {"own_surface_fallbacks", f.ownSurfaceFallbacks},
                        {"buried_vertices", f.buriedVertices}});
    j["frames"] = list;
    AtomicFile file(path);
    file.stream() << j.dump(2) << "\n";
    file.commit();
}

}  // namespace qsgi
