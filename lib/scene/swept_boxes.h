// A few boxes that together hold every pose of a moving instance (docs/design.md §6.5). Its
// bounds frame after frame, with neighbours in time merged where merging adds the least surface
// area, until at most `most` remain. One box over the whole animation (their union) would hold a
// mover that flies across the scene together with most of the scene it flies past, and every
// path through that part would be tracked and every disc there refitted; a few boxes follow the
// mover's way.
#pragma once

#include <cstddef>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

// poses: the instance's bounds in time order (empty ones are skipped). The answer covers every
// one of them, in time order; the same input gives the same boxes.
std::vector<Bounds3f> sweptBoxes(const std::vector<Bounds3f>& poses, size_t most);

}  // namespace qsgi
