// Density estimation (DESIGN §5): from the ray cache to irradiance and radiosity per vertex, by
// impact count, photon map or DETP, with or without spatial indexes.
#pragma once

#include "estimate/detp.h"
#include "estimate/disc_regions.h"
#include "estimate/vertex_radiosity.h"
#include "scene/scene.h"
#include "trace/embree_device.h"
#include "trace/ray_cache.h"
#include "trace/scene_bvh.h"

namespace qsgi {

enum class EstimatorKind { ImpactCount, PhotonMap, Detp };
enum class DetpIndex { Embree, Flann };

struct EstimatorSettings {
    EstimatorKind kind = EstimatorKind::ImpactCount;
    float radius = 0.05f;     // photon map: search radius; DETP: disc radius (scene units)
    int k = 50;               // photon map: neighbours
    bool useIndex = true;     // false: brute force, the paper's "No Ray Caché" (reference for tests)
    bool sortQueries = true;  // Morton-ordered queries; false: input order
    DetpIndex detpIndex = DetpIndex::Embree;
    // Where a disc meets other geometry (DESIGN §5): clip (default) or linear; paper is the
    // published rule (and the textbook photon map), for ablations.
    DetpBoundary boundary = DetpBoundary::Clip;
};

// Whether the estimator needs disc regions, and whether with the photon map's coverage.
bool needsDiscRegions(const EstimatorSettings& settings);
DiscRegions makeDiscRegions(const EstimatorSettings& settings);

// Computes irradiance and radiosity at every vertex of the scene's current pose. bvh holds that
// pose. regions: the disc regions of that pose (makeDiscRegions); computed here when null and
// needed.
VertexRadiosity estimateVertexRadiosity(const Scene& scene, const SceneBvh& bvh, const RayCache& cache,
                                        const EstimatorSettings& settings, const EmbreeDevice& device,
                                        const DiscRegions* regions = nullptr);

const char* estimatorName(EstimatorKind kind);

}  // namespace qsgi
