// What density estimation reads (docs/design.md §5): which estimator, the parameters they share,
// and each one's own (detp_settings.h, photon_map_settings.h; impact count has none). A light
// header: the option table sets these fields directly, and the part of qsgi that reads inputs
// includes it without any of estimation or tracing.
#pragma once

#include "estimate/detp_settings.h"
#include "estimate/photon_map_settings.h"
#include "util/enum_names.h"

namespace qsgi {

enum class EstimatorKind { ImpactCount, PhotonMap, Detp };
inline constexpr NamedValue<EstimatorKind> kEstimatorNames[] = {
    {EstimatorKind::ImpactCount, "impact-count"}, {EstimatorKind::PhotonMap, "photon-map"}, {EstimatorKind::Detp, "detp"}};
inline const char* estimatorName(EstimatorKind kind) { return nameOf(kEstimatorNames, kind); }

struct EstimatorSettings {
    EstimatorKind kind = EstimatorKind::ImpactCount;
    float radius = 0.05f;     // photon map: search radius; DETP: disc radius (scene units)
    bool useIndex = true;     // false: brute force, the paper's "No Ray Caché" (reference for tests)
    bool sortQueries = true;  // Morton-ordered queries; false: input order
    PhotonMapSettings photonMap;
    DetpSettings detp;
};

}  // namespace qsgi
