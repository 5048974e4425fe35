#include "scene/swept_boxes.h"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <queue>
#include <tuple>

namespace qsgi {

namespace {

// Half the surface area: what a box costs the rays that pass it (a flat box still counts).
double halfArea(const Bounds3f& b) {
    const Vec3d d(b.diagonal());
    return d.x * d.y + d.y * d.z + d.z * d.x;
}

Bounds3f unionOf(Bounds3f a, const Bounds3f& b) {
    a.extend(b);
    return a;
}

}  // namespace

std::vector<Bounds3f> sweptBoxes(const std::vector<Bounds3f>& poses, size_t most) {
    // Consecutive equal poses (a pause) are one.
    std::vector<Bounds3f> boxes;
    for (const Bounds3f& b : poses)
        if (!b.empty() && (boxes.empty() || !(boxes.back() == b))) boxes.push_back(b);
    most = std::max<size_t>(most, 1);
    if (boxes.size() <= most) return boxes;
    // Greedy merging of neighbours in a list, cheapest first (ties: the earlier pair), with
    // stale heap entries recognised by their version.
    const size_t n = boxes.size();
    std::vector<size_t> next(n), previous(n);
    std::vector<uint32_t> version(n, 0);
    std::vector<char> alive(n, 1);
    for (size_t i = 0; i < n; ++i) {
        next[i] = i + 1;
        previous[i] = i == 0 ? n : i - 1;
    }
    using Candidate = std::tuple<double, size_t, uint32_t, uint32_t>;  // cost, left, its version, right's
    std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> heap;
    auto offer = [&](size_t left) {
        const size_t right = next[left];
        if (right >= n) return;
        const double cost = halfArea(unionOf(boxes[left], boxes[right])) - halfArea(boxes[left]) - halfArea(boxes[right]);
        heap.emplace(cost, left, version[left], version[right]);
    };
    for (size_t i = 0; i + 1 < n; ++i) offer(i);
    for (size_t count = n; count > most && !heap.empty();) {
        const auto [cost, left, leftVersion, rightVersion] = heap.top();
        heap.pop();
        const size_t right = next[left];
        if (!alive[left] || right >= n || version[left] != leftVersion || version[right] != rightVersion) continue;
        boxes[left].extend(boxes[right]);
        alive[right] = 0;
        next[left] = next[right];
        if (next[left] < n) previous[next[left]] = left;
        ++version[left];
        --count;
        offer(left);
        if (previous[left] < n) offer(previous[left]);  // its pair with `left` changed (and left's version)
    }
    std::vector<Bounds3f> out;
    for (size_t i = 0; i < n; ++i)
        if (alive[i]) out.push_back(boxes[i]);
    return out;
}

}  // namespace qsgi
