// DETP behind the Estimator interface (docs/design.md §5–§6), with its three boundary rules. Per vertex,
// fixed-point sums of the crossings' power (and first moments for `linear`), so an update is
// "+ new − old" to the bit:
//   - a removed segment leaves by the crossings remembered when it entered — no second trace
//     through the discs — at every vertex a move can never touch (their crossings never change);
//     the few discs a move can touch (dynamic vertices and those whose test region meets a
//     moving instance's swept boxes, Scene::sweptBoxes) sit in a small refitted BVH, and removed segments are traced
//     through that one only;
//   - an added segment is traced through every disc once, and its crossings remembered;
//   - a vertex the move touched (its disc moved, or its regions changed) is recomputed from the
//     tracked segments the grid lists around its disc, each tested exactly.
// --no-ray-cache keeps every step index-free (the reference); --detp-index flann has no update
// (its frames are solved from scratch, and timing.json says so).
// After the first bounce only (--direct exact), segments of bounce 0 cross no disc in any of
// these steps: DetpDiscs and the reference functions leave them out where crossings are found,
// so they are never remembered, and the segment lists (and the remembered bounces that index
// into them) stay as they are.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <stdexcept>

#include "estimate/estimator.h"
#include "estimate/morton_order.h"
#include "trace/path_groups.h"
#include "trace/slotted_path_store.h"
#include "util/stopwatch.h"

namespace qsgi {

namespace {

class DetpEstimator final : public Estimator {
public:
    DetpEstimator(const EstimatorSettings& settings, const EstimatorContext& context)
        : settings_(settings), scene_(context.scene), bvh_(context.bvh), device_(context.device),
          regions_(context.regions), progress_(context.progress), moments_(settings.detp.boundary == DetpBoundary::Linear),
          afterFirstBounce_(context.afterFirstBounce) {
        mayBeTouched_ = context.scene.vertexDynamic;
        mayBeTouched_.resize(scene_.vertexCount(), 0);
        if (regions_) {
            // Slightly dilated, so that no rounding between the sweep and a frame's pose can put
            // a frame's moved bounds outside (a larger set only remembers less).
            std::vector<Bounds3f> swept;
            for (const Bounds3f& b : scene_.sweptBoxes)
                if (!b.empty()) swept.push_back(b.expanded(64 * scene_.sceneEpsilon()));
            for (uint32_t v : regions_->touchedBy(scene_, swept, mayBeTouched_)) mayBeTouched_[v] = 1;
        }
    }

    EstimateReport solve(const RayCache& cache, VertexRadiosity& out) override {
        EstimateReport report;
        report.verticesUpdated = scene_.vertexCount();
        quantizer_ = PowerQuantizer(cache.maxPhotonPower);
        const EstimatorSettings& e = settings_;
        if (!e.useIndex) {
            const std::vector<Segment> segments = cache.decodeAll();
            std::vector<const Segment*> all(segments.size());
            for (size_t i = 0; i < all.size(); ++i) all[i] = &segments[i];
            sums_.assign(scene_.vertexCount(), DetpVertexSums());
            bruteForceSums(allVertices(), all);
        } else if (e.detp.index == DetpIndex::Flann) {
            const auto order = e.sortQueries ? mortonOrder(scene_.positions) : inputOrder(scene_.vertexCount());
            out.irradiance = detpFlannCandidates(scene_, cache, e.radius, e.detp.boundary, regions_, &bvh_, order, afterFirstBounce_);
            computeRadiosity(scene_, out);
            return report;
        } else {
            discs().updateDynamic();
            DetpQueryStats counted;
            sums_ = discs_->sums(cache, e.sortQueries, quantizer_, &counted, progress_);
            report.detpCrossings = counted.discHits;
        }
        out.irradiance.resize(scene_.vertexCount());
        for (uint32_t v = 0; v < scene_.vertexCount(); ++v) out.irradiance[v] = irradianceAt(v);
        computeRadiosity(scene_, out);
        return report;
    }

    bool canUpdate() const override { return !(settings_.useIndex && settings_.detp.index == DetpIndex::Flann); }
    // The paper's rule reads no disc regions: only a moved vertex counts differently.
    std::vector<uint32_t> verticesToRecompute(const std::vector<uint32_t>& changed,
                                              const std::vector<uint8_t>& vertexMoved) const override {
        return regions_ ? changed : movedOnly(changed, vertexMoved);
    }
    float reach() const override { return settings_.radius; }

    void prepareUpdates(const TrackedPaths& tracked) override {
        const uint32_t slots = uint32_t(tracked.trackedPaths());
        remembered_ = RememberedStore(slots, {true, moments_});
        if (!settings_.useIndex) return;  // brute force remembers nothing: it is the reference
        // In blocks of paths, so that the crossings found wait in a bounded buffer, not all at once.
        constexpr uint32_t kBlock = 1 << 15;
        std::vector<Segment> block;
        std::vector<SegmentCrossing> found;
        for (uint32_t first = 0; first < slots; first += kBlock) {
            block.clear();
            tracked.segmentsOfSlots(first, std::min(slots, first + kBlock), block);
            discs_->findCrossings(block, DetpDiscs::Discs::Fixed, found);
            // The block holds slots first, first + 1, … in order, one group of segments each.
            uint32_t slot = first;
            size_t next = 0;
            forEachPathGroup(block, [&](size_t, size_t end) {
                const size_t begin = next;
                while (next < found.size() && found[next].segment < end) ++next;
                remembered_.append(slot, uint32_t(next - begin));
                for (size_t c = begin; c < next; ++c) remember(slot, uint32_t(c - begin), block[found[c].segment].bounce, found[c]);
                ++slot;
            });
            // Room for all, extrapolated from the first block: growing a quarter at a time would
            // copy the store about four times over (fresh pages each time: a tenth of the
            // flying block's frame 0 went to them). The first block may cross more discs than
            // the rest (its paths may all come from one light): a guess too high is given back
            // at the end.
            if (first == 0 && slot > 0 && slot < slots)
                remembered_.reserve(std::min<uint64_t>(
                    UINT32_MAX, remembered_.records() + remembered_.records() * (slots - slot) / slot * 17 / 16));
        }
        remembered_.trimReserve();
    }

    EstimateReport update(const FrameChange& change, VertexRadiosity& out) override {
        EstimateReport report;
        std::vector<uint8_t> skip(scene_.vertexCount(), 0);
        for (uint32_t v : change.touched) {
            // The remembered crossings are only right where no move ever reaches.
            if (!mayBeTouched_[v])
                throw std::logic_error("DETP update: vertex " + std::to_string(v) +
                                       " was touched by a move but lies outside every swept instance bound");
            skip[v] = 1;
        }
        std::vector<uint8_t> changed(scene_.vertexCount(), 0);
        Stopwatch clock;
        if (settings_.useIndex) report.crossingsForgotten = updateIndexed(change, skip, changed);
        else updateBruteForce(change, skip, changed);
        report.updateSeconds = clock.seconds();

        clock.restart();
        report.recomputeCandidates = recompute(change.touched, change.tracked);
        report.recomputeSeconds = clock.seconds();
        report.verticesRecomputed = change.touched.size();
        for (uint32_t v : change.touched) changed[v] = 1;
        uint64_t updated = 0;
        for (uint32_t v = 0; v < scene_.vertexCount(); ++v)
            if (changed[v]) {
                out.irradiance[v] = irradianceAt(v);
                ++updated;
            }
        computeRadiosity(scene_, out);
        report.verticesUpdated = updated;
        return report;
    }

    void dropUpdateState() override { remembered_ = RememberedStore(); }

    size_t stateBytes() const override {
        return remembered_.bytes() + sums_.capacity() * sizeof(DetpVertexSums) + mayBeTouched_.capacity();
    }

private:
    // A crossing of a tracked segment at a vertex no move touches: enough to subtract it again.
    // Per tracked path (TrackedPaths::slotOf), its crossings in bounce order; `linear` also keeps
    // each crossing's quantised (x, y).
    struct Remembered {
        uint32_t vertex;
        uint32_t bounce;  // of the segment, within its path
    };
    using Moments = std::array<int32_t, 2>;
    using RememberedStore = SlottedPathStore<Remembered, Moments>;

    DetpDiscs& discs() {
        if (!discs_)
            discs_ = std::make_unique<DetpDiscs>(device_, scene_, settings_.radius, settings_.detp.boundary, regions_, &bvh_,
                                                 &mayBeTouched_, afterFirstBounce_);
        return *discs_;
    }
    std::vector<uint32_t> allVertices() const { return inputOrder(scene_.vertexCount()); }
    Vec3f irradianceAt(uint32_t v) const {
        return detpVertexIrradiance(sums_[v], regions_ ? &(*regions_)[v] : nullptr, settings_.radius, settings_.detp.boundary,
                                    quantizer_);
    }
    // Crossing j of the slot's record.
    void remember(uint32_t slot, uint32_t j, uint32_t bounce, const SegmentCrossing& c) {
        remembered_.at<0>(slot, j) = Remembered{c.vertex, bounce};
        if (moments_) remembered_.at<1>(slot, j) = Moments{DetpVertexSums::momentOf(c.at.x), DetpVertexSums::momentOf(c.at.y)};
    }
    void add(uint32_t v, const Vec3f& power, const DiscCrossing& at, int sign) {
        sums_[v].add(power, at, quantizer_, moments_, sign);
    }

    // + new − old with the disc index and the remembered crossings.
    // Returns how many crossings left by being remembered.
    uint64_t updateIndexed(const FrameChange& change, const std::vector<uint8_t>& skip, std::vector<uint8_t>& changed) {
        uint64_t forgotten = 0;
        discs().updateDynamic();
        const std::vector<Segment>& removed = change.removed;
        const std::vector<Segment>& added = change.added;
        // Removed, at the discs no move touches: by their remembered crossings.
        forEachPathGroup(removed, [&](size_t i, size_t) {
            const uint32_t from = removed[i].bounce;
            const int32_t slot = change.tracked.slotOf(removed[i].path);
            if (slot < 0) return;
            for (uint32_t c = 0; c < remembered_.slot(uint32_t(slot)).count; ++c) {
                const Remembered& r = remembered_.at<0>(uint32_t(slot), c);
                if (r.bounce < from) continue;
                const Segment& s = removed[i + (r.bounce - from)];
                const Moments q = moments_ ? remembered_.at<1>(uint32_t(slot), c) : Moments{0, 0};
                sums_[r.vertex].add(s.power, q[0], q[1], quantizer_, moments_, -1);
                ++forgotten;
                changed[r.vertex] = 1;
            }
        });
        // Removed, at the discs a move can touch: traced through those (few) again.
        std::vector<SegmentCrossing> found;
        discs_->findCrossings(removed, DetpDiscs::Discs::Refitted, found);
        for (const SegmentCrossing& c : found) {
            if (skip[c.vertex]) continue;
            add(c.vertex, removed[c.segment].power, c.at, -1);
            changed[c.vertex] = 1;
        }
        // Added: through every disc once, and remembered where no move can touch. In blocks of
        // whole paths, so that the crossings found wait in a bounded buffer: all of a frame's at
        // once were its largest allocation (Cornell, 10^7 photons: 2.5 M new segments, 17 M
        // crossings, 0.56 GB).
        // First retraced bounce per path, in path order (both lists are in path order).
        std::vector<std::pair<uint32_t, uint32_t>> retraced;
        for (const auto* list : {&removed, &added})
            forEachPathGroup(*list, [&](size_t i, size_t) { retraced.push_back({(*list)[i].path, (*list)[i].bounce}); });
        std::sort(retraced.begin(), retraced.end());
        retraced.erase(std::unique(retraced.begin(), retraced.end(), [](const auto& a, const auto& b) { return a.first == b.first; }),
                       retraced.end());
        constexpr size_t kBlock = 1 << 16;
        std::vector<Segment> block;
        size_t nextPath = 0;
        for (size_t first = 0; first < added.size();) {
            const size_t end = pathGroupEnd(added, std::min(added.size(), first + kBlock) - 1);
            block.assign(added.begin() + int64_t(first), added.begin() + int64_t(end));
            discs_->findCrossings(block, DetpDiscs::Discs::All, found);
            for (const SegmentCrossing& c : found) {
                if (skip[c.vertex]) continue;
                add(c.vertex, block[c.segment].power, c.at, +1);
                changed[c.vertex] = 1;
            }
            const size_t pathsEnd = size_t(std::upper_bound(retraced.begin(), retraced.end(), std::make_pair(block.back().path, UINT32_MAX)) - retraced.begin());
            rememberRetraced(change.tracked, retraced, nextPath, pathsEnd, block, found);
            nextPath = pathsEnd;
            first = end;
        }
        block.clear();
        found.clear();
        rememberRetraced(change.tracked, retraced, nextPath, retraced.size(), block, found);
        remembered_.compactIfWasteful();
        return forgotten;
    }

    // The records of retraced paths [begin, end): the kept head's crossings, then the new tail's
    // (in `added`, with their crossings `found`; both in path order).
    void rememberRetraced(const TrackedPaths& tracked, const std::vector<std::pair<uint32_t, uint32_t>>& retraced, size_t begin, size_t end,
                          const std::vector<Segment>& added, const std::vector<SegmentCrossing>& found) {
        size_t a = 0, next = 0;
        for (size_t i = begin; i < end; ++i) {
            const auto [path, from] = retraced[i];
            const uint32_t slot = uint32_t(tracked.slotOf(path));
            uint32_t keep = 0;
            while (keep < remembered_.slot(slot).count && remembered_.at<0>(slot, keep).bounce < from) ++keep;
            // The path's new segments [a, pathEnd) and their crossings [next, stop).
            while (a < added.size() && added[a].path < path) a = pathGroupEnd(added, a);
            const size_t pathEnd = a < added.size() && added[a].path == path ? pathGroupEnd(added, a) : a;
            while (next < found.size() && found[next].segment < a) ++next;
            size_t stop = next;
            uint32_t fresh = 0;
            for (; stop < found.size() && found[stop].segment < pathEnd; ++stop) fresh += !mayBeTouched_[found[stop].vertex];
            remembered_.rewrite(slot, keep, keep + fresh);
            for (uint32_t j = keep; next < stop; ++next)
                if (!mayBeTouched_[found[next].vertex]) remember(slot, j++, added[found[next].segment].bounce, found[next]);
            a = pathEnd;
        }
    }

    // Index-free (--no-ray-cache): every changed segment against every disc.
    void updateBruteForce(const FrameChange& change, const std::vector<uint8_t>& skip, std::vector<uint8_t>& changed) {
        std::vector<const Segment*> removed, added;
        for (const Segment& s : change.removed) removed.push_back(&s);
        for (const Segment& s : change.added) added.push_back(&s);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, scene_.vertexCount(), 64), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t v = r.begin(); v != r.end(); ++v) {
                if (skip[v]) continue;
                const DetpVertexSums gain = vertexSums(uint32_t(v), added);
                const DetpVertexSums loss = vertexSums(uint32_t(v), removed);
                if (gain == DetpVertexSums() && loss == DetpVertexSums()) continue;
                sums_[v] += gain;
                sums_[v] -= loss;
                changed[v] = 1;
            }
        });
    }

    // The touched vertices from scratch: only tracked segments can cross their discs (the
    // others never meet the envelope, which holds every disc a move touches). Returns the
    // segments gathered for them.
    uint64_t recompute(const std::vector<uint32_t>& vertices, const TrackedPaths& tracked) {
        if (vertices.empty()) return 0;
        if (!settings_.useIndex) {
            std::vector<Segment> segments;
            tracked.allSegments(segments);
            std::vector<const Segment*> all(segments.size());
            for (size_t i = 0; i < all.size(); ++i) all[i] = &segments[i];
            for (uint32_t v : vertices) sums_[v] = DetpVertexSums();
            bruteForceSums(vertices, all);
            return uint64_t(all.size()) * vertices.size();
        }
        // The segments the grid lists in the cells around the recomputed discs (a crossing lies
        // within r of v, on the part of a segment the grid lists), traced once through a BVH of
        // those discs alone.
        const float pad = settings_.radius * 1.001f + 4 * scene_.sceneEpsilon();
        std::vector<Bounds3f> boxes(vertices.size());
        for (size_t i = 0; i < vertices.size(); ++i) {
            boxes[i].extend(scene_.positions[vertices[i]]);
            boxes[i] = boxes[i].expanded(pad);
        }
        std::vector<Segment> near;
        tracked.segmentsNear(boxes, near);
        std::vector<const Segment*> segments(near.size());
        for (size_t i = 0; i < near.size(); ++i) segments[i] = &near[i];
        discs_->recompute(segments, quantizer_, vertices, sums_);
        return segments.size();
    }

    DetpVertexSums vertexSums(uint32_t v, const std::vector<const Segment*>& segments) const {
        return detpVertexSums(scene_, v, segments, settings_.radius, settings_.detp.boundary, regions_, &bvh_, quantizer_,
                              afterFirstBounce_);
    }
    void bruteForceSums(const std::vector<uint32_t>& vertices, const std::vector<const Segment*>& segments) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) sums_[vertices[i]] = vertexSums(vertices[i], segments);
        });
    }

    EstimatorSettings settings_;
    const Scene& scene_;
    const SceneBvh& bvh_;
    const EmbreeDevice& device_;
    const DiscRegions* regions_;
    WorkCounter* progress_;
    bool moments_;
    bool afterFirstBounce_;  // segments of bounce 0 cross no disc
    PowerQuantizer quantizer_{0.0f};
    std::vector<uint8_t> mayBeTouched_;  // per vertex: a move can touch it (its disc is refitted)
    std::unique_ptr<DetpDiscs> discs_;
    std::vector<DetpVertexSums> sums_;
    RememberedStore remembered_;  // per tracked path
};

}  // namespace

std::unique_ptr<Estimator> makeDetpEstimator(const EstimatorSettings& settings, const EstimatorContext& context) {
    return std::make_unique<DetpEstimator>(settings, context);
}

}  // namespace qsgi
