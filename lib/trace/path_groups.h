// Segments in path order come in groups, one per path: a path's segments are consecutive, in
// bounce order (the ray cache's blocks, a retrace's old and new tails, the tracked segments).
#pragma once

#include <cstddef>
#include <vector>

#include "trace/ray_cache.h"

namespace qsgi {

// The end of the group that segment i belongs to.
inline size_t pathGroupEnd(const std::vector<Segment>& segments, size_t i) {
    const uint32_t path = segments[i].path;
    while (i < segments.size() && segments[i].path == path) ++i;
    return i;
}

// visit(begin, end) for each group [begin, end), in order.
template <class Visit>
void forEachPathGroup(const std::vector<Segment>& segments, Visit&& visit) {
    for (size_t i = 0; i < segments.size();) {
        const size_t end = pathGroupEnd(segments, i);
        visit(i, end);
        i = end;
    }
}

}  // namespace qsgi
