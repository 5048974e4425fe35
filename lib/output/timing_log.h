// timing.json (DESIGN §7): the run's configuration, per-frame timings and work counts, and the
// summaries that mirror the paper's table (initial frame vs. per-frame update).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace qsgi {

struct FrameTiming {
    int frame = 0;
    bool fromScratch = true;             // computed from scratch, or by the incremental update
    double findAffectedSeconds = 0, retraceSeconds = 0;  // the parts of an update's photon time
    double photonSimulationSeconds = 0;  // tracing (or retracing) photons
    double estimationSeconds = 0;        // density estimation
    double renderSeconds = 0;            // the camera view (EXR/PNG), excluding file writing
    double writeSeconds = 0;             // PLY, EXR and PNG output
    uint64_t segments = 0;               // segments in the ray cache after this frame
    uint64_t photonsMissingScene = 0;    // photons whose first segment hit nothing
    uint64_t pathsRetraced = 0;
    uint64_t pathsAffectedByImpact = 0, pathsAffectedByBlocking = 0;  // DESIGN §6 step 2 (a), (b)
    uint64_t trackedPaths = 0, trackedSegments = 0, trackedBytes = 0;  // what frames search (§6.5)
    uint64_t segmentsRemoved = 0, segmentsAdded = 0;
    uint64_t verticesUpdated = 0;
    double recomputeSeconds = 0;    // DETP: recomputing the vertices the move touched
    uint64_t verticesRecomputed = 0;
    // Disc regions (DESIGN §5): time, vertices (re)computed this frame, and the vertices with an
    // empty own surface (paper fallback) or no reachable cell (buried: E = 0).
    double discRegionsSeconds = 0;
    uint64_t discRegionsUpdated = 0;
    uint64_t ownSurfaceFallbacks = 0, buriedVertices = 0;
};

// Calls visit(name, member) for every field of a FrameTiming, as named in timing.json: the one
// list that writing and reading (for --resume) share.
template <class Timing, class Visit>
void forEachTimingField(Timing& f, Visit&& visit) {
    visit("frame", f.frame);
    visit("from_scratch", f.fromScratch);
    visit("photon_update_s", f.photonSimulationSeconds);
    visit("find_affected_s", f.findAffectedSeconds);
    visit("retrace_s", f.retraceSeconds);
    visit("paths_affected_by_impact", f.pathsAffectedByImpact);
    visit("paths_affected_by_blocking", f.pathsAffectedByBlocking);
    visit("tracked_paths", f.trackedPaths);
    visit("tracked_segments", f.trackedSegments);
    visit("tracked_bytes", f.trackedBytes);
    visit("recompute_s", f.recomputeSeconds);
    visit("vertices_recomputed", f.verticesRecomputed);
    visit("estimation_s", f.estimationSeconds);
    visit("render_s", f.renderSeconds);
    visit("write_s", f.writeSeconds);
    visit("segments", f.segments);
    visit("photons_missing_scene", f.photonsMissingScene);
    visit("paths_retraced", f.pathsRetraced);
    visit("segments_removed", f.segmentsRemoved);
    visit("segments_added", f.segmentsAdded);
    visit("vertices_updated", f.verticesUpdated);
    visit("disc_regions_s", f.discRegionsSeconds);
    visit("disc_regions_updated", f.discRegionsUpdated);
    visit("own_surface_fallbacks", f.ownSurfaceFallbacks);
    visit("buried_vertices", f.buriedVertices);
}

struct TimingLog {
    // config
    std::string estimator;
    float radius = 0;
    int k = 0;
    bool rayCache = true, sortQueries = true;
    std::string detpIndex;
    std::string boundary;  // DETP / photon-map boundary rule
    uint64_t photons = 0, seed = 0;
    int threads = 0;
    bool fullRecompute = false;
    bool envelope = true;
    bool aimEmission = true;
    uint64_t photonsMissingScene = 0;  // at the run's first frame
    double emittedFraction = 1;        // LightSampler::emittedFraction
    bool emissionMeasured = false;     // the two above are set (after this run's first frame)
    // scene
    std::string scene;
    uint64_t vertices = 0, triangles = 0, dynamicVertices = 0, lights = 0;
    uint64_t degenerateTriangles = 0;
    double animationDiagonal = 0;  // the diagonal of the whole animation's bounds (default radius = 1.5 % of it)
    // runFingerprint of the inputs and settings; --resume continues only a folder whose log has it.
    std::string inputsFingerprint;

    std::vector<FrameTiming> frames;  // in the order they were written

    void write(const std::filesystem::path& path) const;  // atomically
};

// What --resume needs from an earlier run's timing.json: its fingerprint and its frames. Throws
// InputError naming the file if it is not a timing log qsgi wrote.
struct EarlierRun {
    std::string inputsFingerprint;
    std::vector<FrameTiming> frames;
};
EarlierRun readTimingLog(const std::filesystem::path& path);

}  // namespace qsgi
