// DETP's own parameters (docs/design.md §5; the algorithm is detp.h): the rule where a disc meets
// other geometry, and the index that finds the crossings. A light header: the option table sets
// these fields directly.
#pragma once

#include "util/enum_names.h"

namespace qsgi {

// Where a disc meets other geometry: clip (only the cells light can reach from the vertex's side
// count), linear (clip plus a linear fit of the flux density) or paper (the published rule, and
// the textbook photon map: for ablations). The photon map's discs follow the same rule.
enum class DetpBoundary { Clip, Linear, Paper };
inline constexpr NamedValue<DetpBoundary> kDetpBoundaryNames[] = {
    {DetpBoundary::Clip, "clip"}, {DetpBoundary::Linear, "linear"}, {DetpBoundary::Paper, "paper"}};
inline const char* detpBoundaryName(DetpBoundary rule) { return nameOf(kDetpBoundaryNames, rule); }

// How crossings are found: Embree (exact) or FLANN (approximate candidates).
enum class DetpIndex { Embree, Flann };
inline constexpr NamedValue<DetpIndex> kDetpIndexNames[] = {{DetpIndex::Embree, "embree"}, {DetpIndex::Flann, "flann"}};

struct DetpSettings {
    // Read by the photon map too: under paper it uses no disc regions (the textbook photon map).
    DetpBoundary boundary = DetpBoundary::Clip;
    DetpIndex index = DetpIndex::Embree;
};

}  // namespace qsgi
