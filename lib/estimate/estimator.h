// Density estimation (DESIGN §5): from the ray cache to irradiance and radiosity per vertex, by
// impact count, photon map or DETP, with or without spatial indexes.
#pragma once

#include "estimate/vertex_radiosity.h"
#include "scene/scene.h"
#include "trace/embree_device.h"
#include "trace/ray_cache.h"

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
};

// Computes irradiance and radiosity at every vertex of the scene's current pose.
VertexRadiosity estimateVertexRadiosity(const Scene& scene, const RayCache& cache, const EstimatorSettings& settings,
                                        const EmbreeDevice& device);

const char* estimatorName(EstimatorKind kind);

}  // namespace qsgi
