#include "estimate/photon_map.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "estimate/own_surface.h"
#include "estimate/point_grid.h"

namespace qsgi {

namespace {
constexpr float kNeverEstimated = std::numeric_limits<float>::infinity();
constexpr float kNoBall = -1.0f;
}  // namespace

PhotonMap::Impact PhotonMap::impactOf(const Segment& s) {
    return Impact{s.impactPoint(), s.direction, s.power, s.triangle, keyOf(s)};
}

PhotonMap::PhotonMap(const RayCache& cache, const Scene& scene, const SceneBvh* bvh, bool afterFirstBounce)
    : frontNormals_(scene.frontFaceNormals()), bvh_(bvh), quantizer_(cache.maxPhotonPower), afterFirstBounce_(afterFirstBounce) {
    // Per block in parallel, joined in block order: the cache's (path, bounce) order.
    std::vector<std::vector<Impact>> perBlock(cache.blockCount());
    cache.forEachBlock([&](size_t b, const std::vector<Segment>& block) {
        for (const Segment& s : block)
            if (takes(s)) perBlock[b].push_back(impactOf(s));
    });
    size_t total = 0;
    for (const auto& impacts : perBlock) total += impacts.size();
    impacts_.reserve(total);
    for (auto& impacts : perBlock) {
        impacts_.insert(impacts_.end(), impacts.begin(), impacts.end());
        std::vector<Impact>().swap(impacts);
    }
    rebuildBig();
}

// Incremental update

void PhotonMap::rebuildBig() {
    if (bigRemoved_ > 0) {
        size_t live = 0;
        for (size_t i = 0; i < impacts_.size(); ++i)
            if (i >= bigCount_ || !bigDead_[i]) impacts_[live++] = impacts_[i];
        impacts_.resize(live);
    }
    bigCount_ = impacts_.size();
    bigDead_.assign(bigCount_, 0);
    bigRemoved_ = 0;
    bigKeys_.resize(bigCount_);
    for (size_t i = 0; i < bigCount_; ++i) bigKeys_[i] = {impacts_[i].key, uint32_t(i)};
    // A cache traced in one piece comes sorted already.
    if (!std::is_sorted(bigKeys_.begin(), bigKeys_.end())) std::sort(bigKeys_.begin(), bigKeys_.end());
    const auto same = [](const auto& a, const auto& b) { return a.first == b.first; };
    if (std::adjacent_find(bigKeys_.begin(), bigKeys_.end(), same) != bigKeys_.end())
        throw std::logic_error("PhotonMap: two impacts with the same (path, bounce)");
    smallSlots_.clear();
    small_.reset();
    smallStale_ = false;
    std::vector<Vec3f> points(bigCount_);
    for (size_t i = 0; i < bigCount_; ++i) points[i] = impacts_[i].point;
    big_ = std::make_unique<PointIndex>(std::move(points));
}

void PhotonMap::rebuildSmall(float cell) const {
    std::vector<Vec3f> points;
    points.reserve(impacts_.size() - bigCount_);
    for (size_t i = bigCount_; i < impacts_.size(); ++i) points.push_back(impacts_[i].point);
    small_ = points.empty() ? nullptr : std::make_unique<PointGrid>(points, cell);
    smallCell_ = cell;
    smallStale_ = false;
}

int64_t PhotonMap::bigSlot(uint64_t key) const {
    const auto it = std::lower_bound(bigKeys_.begin(), bigKeys_.end(), std::pair<uint64_t, uint32_t>(key, 0));
    if (it == bigKeys_.end() || it->first != key || bigDead_[it->second]) return -1;
    return int64_t(it->second);
}

void PhotonMap::removeImpact(uint64_t key) {
    if (const auto it = smallSlots_.find(key); it != smallSlots_.end()) {
        // The added part is re-indexed before the next query, so it stays packed: the last one
        // fills the hole.
        const uint32_t slot = it->second;
        smallSlots_.erase(it);
        if (slot + 1 != impacts_.size()) {
            impacts_[slot] = impacts_.back();
            smallSlots_[impacts_[slot].key] = slot;
        }
        impacts_.pop_back();
        smallStale_ = true;
        return;
    }
    const int64_t slot = bigSlot(key);
    if (slot < 0) throw std::logic_error("PhotonMap::update: a removed impact is not in the map");
    bigDead_[size_t(slot)] = 1;
    ++bigRemoved_;
    big_->remove(size_t(slot));
}

void PhotonMap::addImpact(const Segment& s) {
    const uint64_t key = keyOf(s);
    if (bigSlot(key) >= 0 || !smallSlots_.emplace(key, uint32_t(impacts_.size())).second)
        throw std::logic_error("PhotonMap::update: an added impact is already in the map");
    impacts_.push_back(impactOf(s));
    smallStale_ = true;
}

void PhotonMap::update(const std::vector<Segment>& removed, const std::vector<Segment>& added, const Scene& scene) {
    for (const Segment& s : removed)
        if (takes(s)) removeImpact(keyOf(s));
    for (const Segment& s : added)
        if (takes(s)) addImpact(s);
    frontNormals_ = scene.frontFaceNormals();
    // Queries pay for the small tree's size and the big tree's dead points; rebuilding costs all
    // impacts. Past a quarter added, or more dead than live, the big tree is rebuilt.
    const size_t bigLive = bigCount_ - bigRemoved_, addedCount = impacts_.size() - bigCount_;
    if (addedCount > bigLive / 4 || bigRemoved_ > bigLive) rebuildBig();
}

// Estimates

PhotonMap::VertexFilter PhotonMap::filterFor(const Scene& scene, const DiscRegions* regions, size_t v) const {
    const VertexDisc* disc = regions && !(*regions)[v].fallback ? &(*regions)[v] : nullptr;
    return VertexFilter{Vec3d(scene.positions[v]), Vec3d(scene.normals[v]), disc, regions ? regions->radius() : 0.0f};
}

bool PhotonMap::counts(const VertexFilter& f, const Impact& impact) const {
    const Vec3f normal(f.normal);
    if (!(dot(impact.direction, normal) < 0)) return false;
    if (!f.disc) return true;
    if (!(dot(frontNormals_[impact.triangle], normal) > kOwnSurfaceCos)) return false;
    const Vec3d offset = Vec3d(impact.point) - f.position;
    const double height = dot(offset, f.normal);
    if (!(height <= double(f.disc->epsAbove) && height >= -double(f.disc->epsBelow))) return false;
    // Only where light can arrive from v's side: not behind a wall beside v, not under a box.
    const double x = dot(offset, Vec3d(f.disc->tangent)) / f.radius, y = dot(offset, Vec3d(f.disc->bitangent)) / f.radius;
    return pointReachable(reachInCell(*f.disc, discCellOf(x, y)), *f.disc, Vec3f(f.position), Vec3f(f.normal), f.radius,
                          x, y, bvh_);
}

Vec3f PhotonMap::estimate(const std::vector<Neighbour>& sortedFront, size_t sorted, const VertexDisc* disc, float radius,
                          int k) const {
    const size_t found = std::min(sorted, size_t(k));
    if (found == 0) return Vec3f(0.0f);
    // With k neighbours, the k-th only marks the radius r_k: it lies on the disc's rim, and
    // counting it biases the estimate by k/(k−1) for a uniform density (E[(k−1)/(π r_k²)] = λ).
    // So the k−1 inside are summed. With fewer than k inside `radius`, the disc is the search
    // disc itself, and every impact in it counts.
    const bool full = found == size_t(k) && k > 1;
    const size_t summed = full ? found - 1 : found;
    PowerSum sum;
    for (size_t i = 0; i < summed; ++i) sum.add(sortedFront[i].power, quantizer_);
    double r = full ? std::sqrt(double(sortedFront[found - 1].distanceSquared)) : double(radius);
    if (!(r > 0)) r = double(radius);  // k coincident impacts: no finite density to report
    // The part of the r disc that surfaces facing n_v cover (all of it without regions).
    double area = disc ? disc->coveredArea(std::min(1.0, r / double(radius))) * double(radius) * double(radius) : M_PI * r * r;
    // Impacts were counted, yet no covered cell lies within r_k: the pattern is too coarse for
    // this radius (a radius beyond the surface's size). Keep the textbook area there.
    if (!(area > 0)) area = summed > 0 ? M_PI * r * r : 0;
    if (!(area > 0)) return Vec3f(0.0f);
    return Vec3f(sum.watts(quantizer_) / area);
}

void PhotonMap::estimateAt(const Scene& scene, const DiscRegions* regions, float radius, int k,
                           const std::vector<uint32_t>& vertices, std::vector<Vec3f>& out, WorkCounter* progress) const {
    if (progress) progress->setTotal(vertices.size());
    if (out.size() != scene.vertexCount()) out.resize(scene.vertexCount(), Vec3f(0.0f));
    if (ballsSquared_.size() != scene.vertexCount()) ballsSquared_.assign(scene.vertexCount(), kNeverEstimated);
    if (keepLists_ && lists_.size() != scene.vertexCount()) lists_.assign(scene.vertexCount(), NeighbourList());
    const float radiusSquared = radius * radius;
    std::vector<uint8_t> queried(vertices.size(), 0);
    const size_t bigLive = big_ ? big_->liveSize() : 0, smallLive = impacts_.size() - bigCount_;
    if (smallLive > 0 && (smallStale_ || !small_ || smallCell_ != radius)) rebuildSmall(radius);
    const size_t most = std::max(bigLive, smallLive);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<Neighbour> front;
        QueryScratch scratch;
        for (size_t q = r.begin(); q != r.end(); ++q) {
            const uint32_t v = vertices[q];
            if (k <= 0) {
                out[v] = Vec3f(0.0f);
                ballsSquared_[v] = kNoBall;
                continue;
            }
            const VertexFilter filter = filterFor(scene, regions, v);
            // Every counted impact nearer than a valid list's bound is in it; at least k are, or
            // the bound is the search radius: the k nearest are the list's (sorted in place: a
            // list's order is free).
            const bool fromList = keepLists_ && lists_[v].valid;
            if (!fromList) {
                queried[q] = 1;
                nearestCounted(scene.positions[v], filter, radiusSquared, k, bigLive, most, scratch, front,
                               keepLists_ ? &lists_[v] : nullptr);
            }
            std::vector<Neighbour>& counted = fromList ? lists_[v].counted : front;
            const size_t keep = std::min(counted.size(), size_t(k));
            std::partial_sort(counted.begin(), counted.begin() + keep, counted.end());
            out[v] = estimate(counted, keep, filter.disc, radius, k);
            ballsSquared_[v] = keep == size_t(k) ? counted[keep - 1].distanceSquared : radiusSquared;
        }
        if (progress) progress->add(r.size());
    });
    lastQueries_ = size_t(std::count(queried.begin(), queried.end(), 1));
}

void PhotonMap::nearestCounted(const Vec3f& p, const VertexFilter& filter, float radiusSquared, int k, size_t bigLive,
                               size_t most, QueryScratch& scratch, std::vector<Neighbour>& front, NeighbourList* list) const {
    std::vector<size_t>& indices = scratch.indices;
    std::vector<float>& d2 = scratch.d2;
    std::vector<std::pair<float, uint32_t>>& candidates = scratch.candidates;  // distance², slot
    // Impacts that do not count are skipped: ask the big tree for twice k neighbours (and the
    // grid for the added impacts within the radius), and if fewer than k of them count, the
    // tree for all within the radius. Distances are recomputed as bruteForce computes them.
    const size_t want = std::min(most, 2 * size_t(k));
    // The added impacts within the radius, every one (the grid has no nearest-first order).
    const float radius = std::sqrt(radiusSquared);
    const auto withinSmall = [&](std::vector<std::pair<float, uint32_t>>& out) {
        if (!small_) return;
        small_->visitNear(p, radius, [&](uint32_t i) {
            const uint32_t slot = uint32_t(bigCount_ + i);
            const float dd = PointIndex::distanceSquared(p, impacts_[slot].point);
            if (dd <= radiusSquared) out.emplace_back(dd, slot);
        });
    };
    candidates.clear();
    // Every live impact nearer than `complete` is among the candidates; beyond it the
    // tree may hold impacts it did not return (ties with its farthest one included).
    float complete = std::numeric_limits<float>::infinity();
    bool all = true;  // the tree returned all its live impacts
    const auto ask = [&](const PointIndex* tree, size_t live, size_t firstSlot, size_t count) {
        const size_t n = std::min(count, live);
        if (n == 0) return;
        tree->nearest(p, n, indices, d2);
        float farthest = 0;
        for (size_t i = 0; i < indices.size(); ++i) {
            const uint32_t slot = uint32_t(firstSlot + indices[i]);
            const float dd = PointIndex::distanceSquared(p, impacts_[slot].point);
            farthest = std::max(farthest, dd);
            candidates.emplace_back(dd, slot);
        }
        if (n < live) {
            complete = std::min(complete, farthest);
            all = false;
        }
    };
    ask(big_.get(), bigLive, 0, want);
    // The added impacts: every one within the radius (complete there, so `complete` is the
    // big tree's alone).
    withinSmall(candidates);
    // Only the candidates nearer than `complete` are tested: past it the k nearest
    // could be missing an impact.
    front.clear();
    for (const auto& [dd, slot] : candidates)
        if ((all || dd < complete) && dd <= radiusSquared && counts(filter, impacts_[slot]))
            front.push_back({dd, impacts_[slot].key, impacts_[slot].power});
    if (all || complete > radiusSquared || front.size() >= size_t(k)) {
        if (list) {
            // What was tested is complete up to `complete` (or the radius).
            list->counted = front;
            list->inclusive = all || complete > radiusSquared;
            list->bound = list->inclusive ? radiusSquared : complete;
            list->valid = true;
        }
        return;
    }
    // Too few counted among the nearest (a vertex beside surfaces its filter rejects):
    // everything within the radius, from one radius search per tree, rather than asking
    // again for ever more neighbours. The same set such a growing search ends with.
    candidates.clear();
    const float padded = radiusSquared * (1.0f + 1e-5f) + std::numeric_limits<float>::min();
    const auto within = [&](const PointIndex* tree, size_t live, size_t firstSlot) {
        if (!tree || live == 0) return;
        tree->withinRadius(p, padded, indices, d2);
        for (size_t i : indices) {
            const uint32_t slot = uint32_t(firstSlot + i);
            candidates.emplace_back(PointIndex::distanceSquared(p, impacts_[slot].point), slot);
        }
    };
    within(big_.get(), bigLive, 0);
    withinSmall(candidates);
    front.clear();
    for (const auto& [dd, slot] : candidates)
        if (dd <= radiusSquared && counts(filter, impacts_[slot]))
            front.push_back({dd, impacts_[slot].key, impacts_[slot].power});
    if (list) {
        list->counted = front;
        list->inclusive = true;
        list->bound = radiusSquared;
        list->valid = true;
    }
}

std::vector<Vec3f> PhotonMap::irradiance(const Scene& scene, const DiscRegions* regions, float radius, int k,
                                         const std::vector<uint32_t>& order) const {
    std::vector<Vec3f> out(scene.vertexCount(), Vec3f(0.0f));
    estimateAt(scene, regions, radius, k, order, out);
    return out;
}

void PhotonMap::irradianceAt(const Scene& scene, const DiscRegions* regions, float radius, int k,
                             const std::vector<uint32_t>& vertices, std::vector<Vec3f>& out, WorkCounter* progress) {
    estimateAt(scene, regions, radius, k, vertices, out, progress);
}

std::vector<Vec3f> PhotonMap::bruteForce(const Scene& scene, const DiscRegions* regions, float radius, int k) const {
    std::vector<Vec3f> out(scene.vertexCount(), Vec3f(0.0f));
    if (k <= 0) return out;
    const float radiusSquared = radius * radius;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, scene.vertexCount(), 16), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<Neighbour> front;
        for (size_t v = r.begin(); v != r.end(); ++v) {
            front.clear();
            const VertexFilter filter = filterFor(scene, regions, v);
            for (size_t i = 0; i < impacts_.size(); ++i) {
                if (i < bigCount_ && bigDead_[i]) continue;
                const float d2 = PointIndex::distanceSquared(scene.positions[v], impacts_[i].point);
                if (d2 <= radiusSquared && counts(filter, impacts_[i])) front.push_back({d2, impacts_[i].key, impacts_[i].power});
            }
            const size_t keep = std::min(front.size(), size_t(k));
            std::partial_sort(front.begin(), front.begin() + keep, front.end());
            out[v] = estimate(front, keep, filter.disc, radius, k);
        }
    });
    return out;
}

// Which estimates a change can alter

void PhotonMap::impactsOf(const std::vector<Segment>& segments, std::vector<Impact>& impacts, std::vector<Vec3f>& points) const {
    for (const Segment& s : segments)
        if (takes(s)) {
            impacts.push_back(impactOf(s));
            points.push_back(impacts.back().point);
        }
}

std::vector<uint32_t> PhotonMap::ballsHolding(const Scene& scene, const DiscRegions* regions,
                                              const std::vector<Segment>& changed) const {
    std::vector<Impact> impacts;
    std::vector<Vec3f> points;
    impactsOf(changed, impacts, points);
    if (impacts.empty()) return {};
    const PointIndex index(std::move(points));
    std::vector<uint8_t> holds(scene.vertexCount(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, scene.vertexCount(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            const float ball = v < ballsSquared_.size() ? ballsSquared_[v] : kNeverEstimated;
            if (ball == kNeverEstimated) {
                holds[v] = 1;
                continue;
            }
            const VertexFilter filter = filterFor(scene, regions, v);
            holds[v] = index.anyWithin(scene.positions[v], ball, [&](size_t i) { return counts(filter, impacts[i]); });
        }
    });
    std::vector<uint32_t> vertices;
    for (size_t v = 0; v < holds.size(); ++v)
        if (holds[v]) vertices.push_back(uint32_t(v));
    return vertices;
}

std::vector<uint32_t> PhotonMap::editLists(const Scene& scene, const DiscRegions* regions, const std::vector<Segment>& changed,
                                           bool entering, int k) {
    if (lists_.size() != scene.vertexCount()) lists_.assign(scene.vertexCount(), NeighbourList());
    std::vector<Impact> impacts;
    std::vector<Vec3f> points;
    impactsOf(changed, impacts, points);
    std::vector<uint8_t> edited(scene.vertexCount(), 0);
    // A grid a list's bound across (a linear-time build: the changed impacts are many, the
    // queries one per vertex).
    float widest = 0;
    for (const NeighbourList& list : lists_)
        if (list.valid) widest = std::max(widest, list.bound);
    const PointGrid grid(points, std::sqrt(widest));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, scene.vertexCount(), 64), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<uint32_t> found;
        for (size_t v = r.begin(); v != r.end(); ++v) {
            NeighbourList& list = lists_[v];
            if (!list.valid) {
                edited[v] = 1;
                continue;
            }
            const Vec3f& p = scene.positions[v];
            found.clear();
            grid.visitNear(p, std::sqrt(list.bound), [&](uint32_t i) { found.push_back(i); });
            if (found.empty()) continue;
            const VertexFilter filter = filterFor(scene, regions, v);
            for (uint32_t i : found) {
                const float dd = PointIndex::distanceSquared(p, impacts[i].point);
                if (!list.holds(dd) || !counts(filter, impacts[i])) continue;
                edited[v] = 1;
                if (entering) {
                    list.counted.push_back({dd, impacts[i].key, impacts[i].power});
                    continue;
                }
                const auto it = std::find_if(list.counted.begin(), list.counted.end(),
                                             [&](const Neighbour& n) { return n.key == impacts[i].key; });
                if (it == list.counted.end()) throw std::logic_error("PhotonMap::editLists: a removed impact is not in its list");
                *it = list.counted.back();
                list.counted.pop_back();
            }
            // Fewer than k inside a bound short of the radius: the k-th lies beyond, unknown.
            if (!entering && !list.inclusive && list.counted.size() < size_t(std::max(k, 0))) list.valid = false;
        }
    });
    std::vector<uint32_t> vertices;
    for (size_t v = 0; v < edited.size(); ++v)
        if (edited[v]) vertices.push_back(uint32_t(v));
    return vertices;
}

size_t PhotonMap::listBytes() const {
    size_t bytes = lists_.capacity() * sizeof(NeighbourList);
    for (const NeighbourList& list : lists_) bytes += list.counted.capacity() * sizeof(Neighbour);
    return bytes;
}

void PhotonMap::forget(const std::vector<uint32_t>& vertices) {
    for (uint32_t v : vertices)
        if (v < lists_.size()) lists_[v].valid = false;
}

}  // namespace qsgi
