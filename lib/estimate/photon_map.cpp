#include "estimate/photon_map.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "estimate/own_surface.h"

namespace qsgi {

PhotonMap::PhotonMap(const RayCache& cache, const Scene& scene, const SceneBvh* bvh)
    : cache_(cache), index_(cache), frontNormals_(scene.frontFaceNormals()), bvh_(bvh), quantizer_(cache.maxPhotonPower) {}

PhotonMap::VertexFilter PhotonMap::filterFor(const Scene& scene, const DiscRegions* regions, size_t v) const {
    const VertexDisc* disc = regions && !(*regions)[v].fallback ? &(*regions)[v] : nullptr;
    return VertexFilter{Vec3d(scene.positions[v]), Vec3d(scene.normals[v]), disc, regions ? regions->radius() : 0.0f};
}

bool PhotonMap::counts(const VertexFilter& f, uint32_t impact) const {
    const Segment& s = segmentOf(impact);
    const Vec3f normal(f.normal);
    if (!(dot(s.direction, normal) < 0)) return false;
    if (!f.disc) return true;
    if (!(dot(frontNormals_[s.triangle], normal) > kOwnSurfaceCos)) return false;
    const Vec3d offset = Vec3d(index_.point(impact)) - f.position;
    const double height = dot(offset, f.normal);
    if (!(height <= double(f.disc->epsAbove) && height >= -double(f.disc->epsBelow))) return false;
    // Only where light can arrive from v's side: not behind a wall beside v, not under a box.
    const double x = dot(offset, Vec3d(f.disc->tangent)) / f.radius, y = dot(offset, Vec3d(f.disc->bitangent)) / f.radius;
    return pointReachable(reachInCell(*f.disc, discCellOf(x, y)), *f.disc, Vec3f(f.position), Vec3f(f.normal), f.radius,
                          x, y, bvh_);
}

Vec3f PhotonMap::estimate(const std::vector<Neighbour>& sortedFront, const VertexDisc* disc, float radius, int k) const {
    const size_t found = std::min(sortedFront.size(), size_t(k));
    if (found == 0) return Vec3f(0.0f);
    // With k neighbours, the k-th only marks the radius r_k: it lies on the disc's rim, and
    // counting it biases the estimate by k/(k−1) for a uniform density (E[(k−1)/(π r_k²)] = λ).
    // So the k−1 inside are summed. With fewer than k inside `radius`, the disc is the search
    // disc itself, and every impact in it counts.
    const bool full = found == size_t(k) && k > 1;
    const size_t summed = full ? found - 1 : found;
    PowerSum sum;
    for (size_t i = 0; i < summed; ++i) sum.add(segmentOf(sortedFront[i].impact).power, quantizer_);
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

std::vector<Vec3f> PhotonMap::irradiance(const Scene& scene, const DiscRegions* regions, float radius, int k,
                                         const std::vector<uint32_t>& order) const {
    std::vector<Vec3f> out(scene.vertexCount(), Vec3f(0.0f));
    if (index_.size() == 0 || k <= 0) return out;
    const float radiusSquared = radius * radius;
    const size_t n = index_.size();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, order.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<size_t> indices;
        std::vector<float> d2;
        std::vector<Neighbour> front;
        for (size_t q = r.begin(); q != r.end(); ++q) {
            const uint32_t v = order[q];
            const VertexFilter filter = filterFor(scene, regions, v);
            // Impacts that do not count are skipped, so ask the tree for more neighbours until k
            // counted ones are found or the candidates run past the radius.
            size_t want = std::min(n, size_t(2 * k));
            // Distances are recomputed as bruteForce computes them, and the search grows until no
            // impact beyond the candidates can tie with the k-th counted one.
            while (true) {
                index_.nearest(scene.positions[v], want, indices, d2);
                front.clear();
                float farthest = 0;
                for (size_t i = 0; i < want; ++i) {
                    const float dd = PointIndex::distanceSquared(scene.positions[v], index_.point(indices[i]));
                    farthest = std::max(farthest, dd);
                    if (dd <= radiusSquared && counts(filter, uint32_t(indices[i]))) front.push_back(neighbour(dd, uint32_t(indices[i])));
                }
                std::sort(front.begin(), front.end());
                if (want == n || farthest > radiusSquared) break;
                if (front.size() >= size_t(k) && farthest > front[size_t(k) - 1].distanceSquared) break;
                want = std::min(n, want * 4);
            }
            out[v] = estimate(front, filter.disc, radius, k);
        }
    });
    return out;
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
            for (size_t i = 0; i < index_.size(); ++i) {
                const float d2 = PointIndex::distanceSquared(scene.positions[v], index_.point(i));
                if (d2 <= radiusSquared && counts(filter, uint32_t(i))) front.push_back(neighbour(d2, uint32_t(i)));
            }
            const size_t keep = std::min(front.size(), size_t(k));
            std::partial_sort(front.begin(), front.begin() + keep, front.end());
            front.resize(keep);
            out[v] = estimate(front, filter.disc, radius, k);
        }
    });
    return out;
}

}  // namespace qsgi
