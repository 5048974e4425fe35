#include "estimate/impact_count.h"

namespace qsgi {

ImpactCount::ImpactCount(const Scene& scene) : sums_(scene.triangleCount()) { updateGeometry(scene); }

void ImpactCount::updateGeometry(const Scene& scene) {
    const size_t n = scene.triangleCount();
    frontNormal_ = scene.frontFaceNormals();
    area_.resize(n);
    degenerate_ = 0;
    for (uint32_t t = 0; t < n; ++t) {
        area_[t] = scene.triangleArea(t);
        if (!(area_[t] > 0)) ++degenerate_;
    }
}

bool ImpactCount::counts(const Segment& s) const {
    return s.hasImpact() && dot(s.direction, frontNormal_[s.triangle]) < 0;
}

void ImpactCount::accumulate(const RayCache& cache) {
    std::fill(sums_.begin(), sums_.end(), PowerSum{});
    const PowerQuantizer q(cache.maxPhotonPower);
    for (const Segment& s : cache.segments)
        if (counts(s)) sums_[s.triangle].add(s.power, q);
}

void ImpactCount::add(const Segment& s, const PowerQuantizer& q) {
    if (counts(s)) sums_[s.triangle].add(s.power, q);
}

void ImpactCount::subtract(const Segment& s, const PowerQuantizer& q) {
    if (counts(s)) sums_[s.triangle].subtract(s.power, q);
}

VertexRadiosity ImpactCount::estimate(const Scene& scene, const PowerQuantizer& q) const {
    std::vector<Vec3d> sum(scene.vertexCount(), Vec3d(0.0));
    std::vector<uint32_t> count(scene.vertexCount(), 0);
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        if (!(area_[t] > 0)) continue;
        const Vec3d e = sums_[t].watts(q) / double(area_[t]);
        for (uint32_t v : scene.triangles[t].v) {
            sum[v] += e;
            ++count[v];
        }
    }
    VertexRadiosity out;
    out.irradiance.resize(scene.vertexCount());
    for (size_t v = 0; v < scene.vertexCount(); ++v)
        out.irradiance[v] = count[v] ? Vec3f(sum[v] / double(count[v])) : Vec3f(0.0f);
    computeRadiosity(scene, out);
    return out;
}

}  // namespace qsgi
