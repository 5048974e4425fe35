// Spatially coherent query order (the paper's "Sort Queries"): points sorted along a 3-D Morton
// (Z-order) curve, so consecutive queries touch the same parts of an index and of memory.
#pragma once

#include <cstdint>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

// Indices of `points` in Morton order (ties broken by index, so the order is deterministic).
std::vector<uint32_t> mortonOrder(const std::vector<Vec3f>& points);

// The identity order 0..n-1 (queries in input order).
std::vector<uint32_t> inputOrder(size_t n);

}  // namespace qsgi
