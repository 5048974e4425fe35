// The photon map behind the Estimator interface (docs/design.md §5, §6 step 4). Its k nearest
// neighbours cannot be folded into sums, so the map keeps every impact in a kd-tree that an
// update edits in place (removed impacts out, added ones in), and, when frames follow, each
// vertex's neighbour list: every counted impact within a bound at least as far as its k-th.
// A frame's removed and added impacts edit the lists that hold them; only the vertices whose
// list changed (whose ball holds a changed impact: on the rim too, by the tie rule) are
// estimated again, from the list alone, and the trees are queried only for the vertices the
// move touched and those whose list fell short of k. Ties are ordered by (path, bounce), so the
// answer does not depend on what the index holds where.
#include <algorithm>
#include <optional>

#include "estimate/estimator.h"
#include "estimate/morton_order.h"
#include "estimate/photon_map.h"
#include "util/stopwatch.h"

namespace qsgi {

namespace {

class PhotonMapEstimator final : public Estimator {
public:
    PhotonMapEstimator(const EstimatorSettings& settings, const EstimatorContext& context)
        : settings_(settings), scene_(context.scene), bvh_(context.bvh), regions_(context.regions),
          keepLists_(context.updatesFollow && settings.useIndex), progress_(context.progress),
          afterFirstBounce_(context.afterFirstBounce) {}

    EstimateReport solve(const RayCache& cache, VertexRadiosity& out) override {
        map_.emplace(cache, scene_, &bvh_, afterFirstBounce_);
        map_->keepLists(keepLists_);
        const EstimatorSettings& e = settings_;
        if (e.useIndex) {
            out.irradiance.assign(scene_.vertexCount(), Vec3f(0.0f));
            map_->irradianceAt(scene_, regions_, e.radius, e.photonMap.k, queryOrder(inputOrder(scene_.vertexCount())), out.irradiance,
                               progress_);
        } else {
            out.irradiance = map_->bruteForce(scene_, regions_, e.radius, e.photonMap.k);
        }
        computeRadiosity(scene_, out);
        EstimateReport report;
        report.verticesUpdated = scene_.vertexCount();
        return report;
    }

    float reach() const override { return 0.0f; }  // impacts only
    void prepareUpdates(const TrackedPaths&) override {}

    EstimateReport update(const FrameChange& change, VertexRadiosity& out) override {
        const EstimatorSettings& e = settings_;
        EstimateReport report;
        Stopwatch clock;
        // The lists (or, without them, the balls) of the previous frame that a changed impact
        // which counts there enters or leaves: the removed ones judged with the triangles as
        // they were, the added ones after. The touched vertices are queried afresh.
        std::vector<uint32_t> vertices, entered;
        if (keepLists_) {
            // First: a touched vertex's filter changed, its list no longer matches it.
            map_->forget(change.touched);
            vertices = map_->editLists(scene_, regions_, change.removed, false, e.photonMap.k);
            map_->update(change.removed, change.added, scene_);
            entered = map_->editLists(scene_, regions_, change.added, true, e.photonMap.k);
        } else if (e.useIndex) {
            vertices = map_->ballsHolding(scene_, regions_, change.removed);
            map_->update(change.removed, change.added, scene_);
            entered = map_->ballsHolding(scene_, regions_, change.added);
        } else {
            map_->update(change.removed, change.added, scene_);  // brute force estimates every vertex below
        }
        vertices.insert(vertices.end(), entered.begin(), entered.end());
        vertices.insert(vertices.end(), change.touched.begin(), change.touched.end());
        std::sort(vertices.begin(), vertices.end());
        vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
        report.updateSeconds = clock.seconds();
        clock.restart();
        if (e.useIndex) {
            map_->irradianceAt(scene_, regions_, e.radius, e.photonMap.k, queryOrder(vertices), out.irradiance);
        } else {
            out.irradiance = map_->bruteForce(scene_, regions_, e.radius, e.photonMap.k);
            vertices = inputOrder(scene_.vertexCount());
        }
        computeRadiosity(scene_, out);
        report.recomputeSeconds = clock.seconds();
        // Updated: estimated again; recomputed: from a fresh query of the trees.
        report.verticesUpdated = vertices.size();
        report.verticesRecomputed = e.useIndex ? map_->lastQueries() : vertices.size();
        return report;
    }

    size_t stateBytes() const override { return map_ && keepLists_ ? map_->listBytes() : 0; }

private:
    // Morton order of the given vertices (coherent queries), unless input order was asked for.
    std::vector<uint32_t> queryOrder(const std::vector<uint32_t>& vertices) const {
        if (!settings_.sortQueries) return vertices;
        std::vector<Vec3f> points(vertices.size());
        for (size_t i = 0; i < vertices.size(); ++i) points[i] = scene_.positions[vertices[i]];
        std::vector<uint32_t> order = mortonOrder(points);
        for (uint32_t& i : order) i = vertices[i];
        return order;
    }

    EstimatorSettings settings_;
    const Scene& scene_;
    const SceneBvh& bvh_;
    const DiscRegions* regions_;
    bool keepLists_;  // updates follow: neighbour lists kept (indexed only; brute force is the reference)
    WorkCounter* progress_;
    bool afterFirstBounce_;  // the map holds the impacts of bounces ≥ 1 only
    std::optional<PhotonMap> map_;
};

}  // namespace

std::unique_ptr<Estimator> makePhotonMapEstimator(const EstimatorSettings& settings, const EstimatorContext& context) {
    return std::make_unique<PhotonMapEstimator>(settings, context);
}

}  // namespace qsgi
