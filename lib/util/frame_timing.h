// One frame's record in timing.json (docs/design.md §7): what computing it cost and changed. The
// stages do not write here: each returns a report of what it measured (the estimator's
// EstimateReport, VertexGeometry's GeometryReport, the second pass's SecondPassReport, ...), and the
// solver (FrameSolver, OutputFrameSolver) and the run (render and write times) assemble the
// record; no logic reads it back. forEachTimingField is the one list that writing and reading
// (for --resume) share, so a new counter is one member and one line.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "util/file_record.h"

namespace qsgi {

struct FrameTiming {
    int frame = 0;
    bool fromScratch = true;  // computed from scratch, or by the incremental update
    // Why a frame after a run's first was computed from scratch: "full-recompute", "estimator"
    // (the estimator has no update, e.g. --detp-index flann) or "change-too-large" (updating would
    // cost more than recomputing, judged from counts). "" for a frame updated incrementally and for
    // the run's first frame, which is always from scratch (fromScratch says so).
    std::string fromScratchReason;
    // What updating this frame was predicted to cost, in shares of a from-scratch frame, from
    // counts before any work (FrameSolver::predictedUpdateShare; 0 where nothing was predicted:
    // a frame nothing moved in, --full-recompute; where the tracking build alone passes 0.8, that
    // build's share; at the first frame, the look-ahead's median, else 0).
    double predictedUpdateShare = 0;
    double findAffectedSeconds = 0, retraceSeconds = 0;  // the parts of an update's photon time
    double photonSimulationSeconds = 0;  // tracing (or finding and retracing) photons
    double estimationSeconds = 0;        // density estimation, disc regions included
    double estimatorUpdateSeconds = 0;   // of which: + new − old at the vertices that keep sums
    double renderSeconds = 0;            // the camera view (EXR/PNG), excluding file writing
    double writeSeconds = 0;             // PLY, EXR and PNG output
    uint64_t segments = 0;               // segments in the ray cache after this frame
    uint64_t photonsMissingScene = 0;    // photons whose first segment hit nothing
    uint64_t pathsRetraced = 0;
    uint64_t pathsAffectedByImpact = 0, pathsAffectedByBlocking = 0;  // docs/design.md §6 step 2 (a), (b)
    uint64_t impactCandidates = 0;    // (a): tracked segments listed on the moved triangles
    uint64_t blockingCandidates = 0;  // (b): tracked segments the grid handed to the exact test
    uint64_t trackedPaths = 0, trackedSegments = 0, trackedBytes = 0;  // what frames search (§6.5)
    uint64_t estimatorStateBytes = 0;  // the estimator's incremental state (remembered crossings…)
    uint64_t segmentsRemoved = 0, segmentsAdded = 0;
    uint64_t verticesUpdated = 0;
    double recomputeSeconds = 0;  // the vertices the move touched, from the segments near them
    uint64_t verticesRecomputed = 0;
    uint64_t recomputeCandidates = 0;  // segments gathered for those recomputations
    uint64_t crossingsForgotten = 0;   // DETP: removed crossings subtracted as remembered, untraced
    uint64_t detpCrossings = 0;        // DETP: the (segment, disc) crossings a from-scratch solve counted
    // Disc regions (docs/design.md §5): time, vertices (re)computed this frame, and the vertices with an
    // empty own surface (paper fallback) or no reachable cell (buried: E = 0).
    double discRegionsSeconds = 0;
    uint64_t discRegionsUpdated = 0;
    uint64_t discRegionsRays = 0;           // rays they traced (DiscRegions::Work)
    uint64_t discRegionsStaticSkipped = 0;  // vertices whose static rays needed no asking
    uint64_t ownSurfacesProved = 0;         // vertices whose ε⁺ OwnSurfaceTree proved without the walk
    uint64_t ownSurfaceFallbacks = 0, buriedVertices = 0;
    // The second pass (--direct exact, --gather M; docs/design.md §5.1): time and rays cast this
    // frame for exact direct light and for the final gather (which includes combining the passes).
    double directSeconds = 0, gatherSeconds = 0;
    uint64_t shadowRays = 0, gatherRays = 0;
    // With the gather cache (--gather-cache A): the vertices that gathered all M rays (the rest
    // are interpolated; 0 without the cache).
    uint64_t gatherRecords = 0;
    // --vertex-fit least-squares (lib/estimate/vertex_fit.h): the fit's time, the meshes whose
    // system was factorised afresh (the others' weights and geometry were unchanged), and the
    // output vertices whose fitted irradiance was negative in some channel and written as 0.
    double fitSeconds = 0;
    uint64_t fitFactorisations = 0, fitClampedVertices = 0;
    uint64_t fitBytes = 0;  // kept across frames: each mesh's matrix and factorisation
    // The frame's files as written, which --resume verifies before it trusts them ("files" in
    // timing.json; not a timing, so not in forEachTimingField's list).
    std::vector<FileRecord> files;
};

template <class Timing, class Visit>
void forEachTimingField(Timing& f, Visit&& visit) {
    visit("frame", f.frame);
    visit("from_scratch", f.fromScratch);
    visit("from_scratch_reason", f.fromScratchReason);
    visit("predicted_update_share", f.predictedUpdateShare);
    visit("photon_update_s", f.photonSimulationSeconds);
    visit("find_affected_s", f.findAffectedSeconds);
    visit("retrace_s", f.retraceSeconds);
    visit("paths_affected_by_impact", f.pathsAffectedByImpact);
    visit("paths_affected_by_blocking", f.pathsAffectedByBlocking);
    visit("impact_candidates", f.impactCandidates);
    visit("blocking_candidates", f.blockingCandidates);
    visit("tracked_paths", f.trackedPaths);
    visit("tracked_segments", f.trackedSegments);
    visit("tracked_bytes", f.trackedBytes);
    visit("estimator_state_bytes", f.estimatorStateBytes);
    visit("estimator_update_s", f.estimatorUpdateSeconds);
    visit("recompute_s", f.recomputeSeconds);
    visit("vertices_recomputed", f.verticesRecomputed);
    visit("recompute_candidates", f.recomputeCandidates);
    visit("crossings_forgotten", f.crossingsForgotten);
    visit("estimation_s", f.estimationSeconds);
    visit("render_s", f.renderSeconds);
    visit("write_s", f.writeSeconds);
    visit("segments", f.segments);
    visit("photons_missing_scene", f.photonsMissingScene);
    visit("paths_retraced", f.pathsRetraced);
    visit("segments_removed", f.segmentsRemoved);
    visit("segments_added", f.segmentsAdded);
    visit("vertices_updated", f.verticesUpdated);
    visit("detp_crossings", f.detpCrossings);
    visit("disc_regions_s", f.discRegionsSeconds);
    visit("disc_regions_updated", f.discRegionsUpdated);
    visit("disc_regions_rays", f.discRegionsRays);
    visit("disc_regions_static_skipped", f.discRegionsStaticSkipped);
    visit("own_surfaces_proved", f.ownSurfacesProved);
    visit("own_surface_fallbacks", f.ownSurfaceFallbacks);
    visit("buried_vertices", f.buriedVertices);
    visit("direct_s", f.directSeconds);
    visit("shadow_rays", f.shadowRays);
    visit("gather_s", f.gatherSeconds);
    visit("gather_rays", f.gatherRays);
    visit("gather_records", f.gatherRecords);
    visit("fit_s", f.fitSeconds);
    visit("fit_factorisations", f.fitFactorisations);
    visit("fit_clamped_vertices", f.fitClampedVertices);
    visit("fit_bytes", f.fitBytes);
}

}  // namespace qsgi
