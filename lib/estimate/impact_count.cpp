#include "estimate/impact_count.h"

#include <tbb/enumerable_thread_specific.h>

namespace qsgi {

ImpactCount::ImpactCount(const Scene& scene, bool afterFirstBounce)
    : sums_(scene.triangleCount()), afterFirstBounce_(afterFirstBounce) {
    updateGeometry(scene);
    vertexTrianglesBegin_.assign(scene.vertexCount() + 1, 0);
    for (const Triangle& t : scene.triangles)
        for (uint32_t v : t.v) ++vertexTrianglesBegin_[v + 1];
    for (size_t v = 0; v < scene.vertexCount(); ++v) vertexTrianglesBegin_[v + 1] += vertexTrianglesBegin_[v];
    vertexTriangles_.resize(vertexTrianglesBegin_.back());
    std::vector<uint32_t> fill(vertexTrianglesBegin_.begin(), vertexTrianglesBegin_.end() - 1);
    for (uint32_t t = 0; t < scene.triangleCount(); ++t)
        for (uint32_t v : scene.triangles[t].v) vertexTriangles_[fill[v]++] = t;
}

void ImpactCount::updateGeometry(const Scene& scene, const std::vector<uint32_t>& triangles) {
    for (uint32_t t : triangles) {
        const bool wasDegenerate = !(area_[t] > 0);
        frontNormal_[t] = frontFaceNormal(scene.positions, scene.normals, scene.triangles[t]);
        area_[t] = scene.triangleArea(t);
        degenerate_ += uint32_t(!(area_[t] > 0)) - uint32_t(wasDegenerate);
    }
}

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
    if (afterFirstBounce_ && !s.scattered) return false;
    return s.hasImpact() && dot(s.direction, frontNormal_[s.triangle]) < 0;
}

void ImpactCount::accumulate(const RayCache& cache) {
    std::fill(sums_.begin(), sums_.end(), PowerSum{});
    const PowerQuantizer q(cache.maxPhotonPower);
    // Fixed-point sums do not depend on the order they are added in: per-thread sums, joined.
    tbb::enumerable_thread_specific<std::vector<PowerSum>> perThread([&] { return std::vector<PowerSum>(sums_.size()); });
    cache.forEachBlock([&](size_t, const std::vector<Segment>& block) {
        std::vector<PowerSum>& sums = perThread.local();
        for (const Segment& s : block)
            if (counts(s)) sums[s.triangle].add(s.power, q);
    });
    for (const auto& sums : perThread)
        for (size_t t = 0; t < sums_.size(); ++t) sums_[t] += sums[t];
}

void ImpactCount::add(const Segment& s, const PowerQuantizer& q) {
    if (counts(s)) sums_[s.triangle].add(s.power, q);
}

void ImpactCount::subtract(const Segment& s, const PowerQuantizer& q) {
    if (counts(s)) sums_[s.triangle].subtract(s.power, q);
}

Vec3f ImpactCount::vertexIrradiance(uint32_t v, const PowerQuantizer& q) const {
    Vec3d sum(0.0);
    uint32_t count = 0;
    for (uint32_t i = vertexTrianglesBegin_[v]; i < vertexTrianglesBegin_[v + 1]; ++i) {
        const uint32_t t = vertexTriangles_[i];
        if (!(area_[t] > 0)) continue;
        sum += sums_[t].watts(q) / double(area_[t]);
        ++count;
    }
    return count ? Vec3f(sum / double(count)) : Vec3f(0.0f);
}

VertexRadiosity ImpactCount::estimate(const Scene& scene, const PowerQuantizer& q) const {
    VertexRadiosity out;
    out.irradiance.resize(scene.vertexCount());
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) out.irradiance[v] = vertexIrradiance(v, q);
    computeRadiosity(scene, out);
    return out;
}

void ImpactCount::estimateAt(const Scene& scene, const PowerQuantizer& q, const std::vector<uint32_t>& vertices,
                             VertexRadiosity& out) const {
    for (uint32_t v : vertices) out.irradiance[v] = vertexIrradiance(v, q);
    computeRadiosity(scene, out);
}

}  // namespace qsgi
