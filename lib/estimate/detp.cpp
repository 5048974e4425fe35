#include "estimate/detp.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "estimate/fixed_point_power.h"
#include "estimate/impact_index.h"
#include "estimate/morton_order.h"

namespace qsgi {

bool segmentCrossesDisc(const Segment& s, const Vec3f& centre, const Vec3f& normal, float radius) {
    const Vec3d d(s.direction), n(normal), o(s.origin), v(centre);
    const double dn = dot(d, n);
    if (!(dn < 0)) return false;  // front side only
    const double tStar = dot(v - o, n) / dn;
    if (!(tStar > 0 && tStar <= double(s.length) + double(radius))) return false;
    const Vec3d offset = o + d * tStar - v;
    return dot(offset, offset) <= double(radius) * double(radius);
}

namespace {

using VertexSums = std::vector<PowerSum>;

std::vector<Vec3f> toIrradiance(const VertexSums& sums, const PowerQuantizer& q, float radius) {
    std::vector<Vec3f> out(sums.size());
    const double area = M_PI * double(radius) * double(radius);
    for (size_t v = 0; v < sums.size(); ++v) out[v] = Vec3f(sums[v].watts(q) / area);
    return out;
}

// Integer sums are order-independent, so per-thread partial sums combine to the same bits for
// any thread count and schedule.
VertexSums combine(tbb::enumerable_thread_specific<VertexSums>& perThread, size_t vertices) {
    VertexSums total(vertices);
    for (const VertexSums& part : perThread)
        for (size_t v = 0; v < vertices; ++v) total[v] += part[v];
    return total;
}

// What the Embree filter needs to apply the exact test, passed through the intersect context.
struct DiscQueryContext {
    RTCIntersectContext base;  // first member: Embree hands back a pointer to it
    const Segment* segment;
    const Scene* scene;
    float radius;
    std::vector<uint32_t>* crossed;
};

void recordCrossedDisc(const RTCFilterFunctionNArguments* args) {
    auto* ctx = reinterpret_cast<DiscQueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const uint32_t v = RTCHitN_primID(args->hit, args->N, i);
        if (segmentCrossesDisc(*ctx->segment, ctx->scene->positions[v], ctx->scene->normals[v], ctx->radius))
            ctx->crossed->push_back(v);
        args->valid[i] = 0;  // reject, so traversal goes on to every other disc along the ray
    }
}

}  // namespace

DetpDiscs::DetpDiscs(const EmbreeDevice& device, const Scene& scene, float radius)
    : scene_(scene), radius_(radius), discs_(device) {
    const size_t n = scene.vertexCount();
    const float extent = std::max(1.0f, scene.bounds().extent());
    rayExtension_ = 1e-4f * radius + 1e-6f * extent;
    RTCGeometry geom = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    auto* vertex = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), n));
    auto* normal = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), n));
    device.checkError("allocating DETP disc buffers");
    // Enlarged discs make Embree's float test a superset of the exact one; the filter decides.
    const float searchRadius = radius * (1 + 1e-3f) + 1e-6f * extent;
    for (size_t v = 0; v < n; ++v) {
        const Vec3f& p = scene.positions[v];
        vertex[4 * v] = p.x;
        vertex[4 * v + 1] = p.y;
        vertex[4 * v + 2] = p.z;
        vertex[4 * v + 3] = searchRadius;
        normal[3 * v] = scene.normals[v].x;
        normal[3 * v + 1] = scene.normals[v].y;
        normal[3 * v + 2] = scene.normals[v].z;
    }
    rtcSetGeometryIntersectFilterFunction(geom, recordCrossedDisc);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(discs_.get(), geom);
    rtcReleaseGeometry(geom);
    rtcSetSceneFlags(discs_.get(), RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(discs_.get(), RTC_BUILD_QUALITY_HIGH);
    rtcCommitScene(discs_.get());
    device.checkError("building the DETP disc BVH");
}

std::vector<Vec3f> DetpDiscs::irradiance(const RayCache& cache, const std::vector<uint32_t>& order,
                                         DetpQueryStats* stats) const {
    const size_t vertices = scene_.vertexCount();
    const PowerQuantizer q(cache.maxPhotonPower);
    tbb::enumerable_thread_specific<VertexSums> perThread([&] { return VertexSums(vertices); });
    tbb::enumerable_thread_specific<uint64_t> hitCount(0);
    // Start the ray a little before the segment and end it a little past t + r, so plane
    // crossings at t* ≈ 0 or t* ≈ t + r reach the exact test rather than Embree's bounds.
    const float slack = rayExtension_;
    // A reordering is gathered into a copy first, so tracing streams through memory instead of
    // jumping through the cache by index (which costs more than the coherence gains).
    bool inputOrder = order.size() == cache.segments.size();
    for (size_t i = 0; i < order.size() && inputOrder; ++i) inputOrder = order[i] == i;
    std::vector<Segment> gathered;
    if (!inputOrder) {
        gathered.resize(order.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, order.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) gathered[i] = cache.segments[order[i]];
        });
    }
    const Segment* ordered = inputOrder ? cache.segments.data() : gathered.data();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, order.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        VertexSums& sums = perThread.local();
        uint64_t& hits = hitCount.local();
        std::vector<uint32_t> crossed;
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const Segment& s = ordered[i];
            crossed.clear();
            DiscQueryContext ctx;
            rtcInitIntersectContext(&ctx.base);
            ctx.segment = &s;
            ctx.scene = &scene_;
            ctx.radius = radius_;
            ctx.crossed = &crossed;
            RTCRayHit rh;
            const Vec3f o = s.origin - s.direction * slack;
            rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
            rh.ray.dir_x = s.direction.x; rh.ray.dir_y = s.direction.y; rh.ray.dir_z = s.direction.z;
            rh.ray.tnear = 0;
            rh.ray.tfar = s.length + radius_ + 2 * slack;
            rh.ray.time = 0;
            rh.ray.mask = 0xFFFFFFFFu;
            rh.ray.id = 0;
            rh.ray.flags = 0;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(discs_.get(), &ctx.base, &rh);
            // Embree may report a primitive more than once along one ray (NOTES.md).
            std::sort(crossed.begin(), crossed.end());
            crossed.erase(std::unique(crossed.begin(), crossed.end()), crossed.end());
            for (uint32_t v : crossed) sums[v].add(s.power, q);
            hits += crossed.size();
        }
    });
    if (stats)
        for (uint64_t h : hitCount) stats->discHits += h;
    return toIrradiance(combine(perThread, vertices), q, radius_);
}

std::vector<Vec3f> detpBruteForce(const Scene& scene, const RayCache& cache, float radius) {
    const PowerQuantizer q(cache.maxPhotonPower);
    VertexSums sums(scene.vertexCount());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, scene.vertexCount(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v)
            for (const Segment& s : cache.segments)
                if (segmentCrossesDisc(s, scene.positions[v], scene.normals[v], radius)) sums[v].add(s.power, q);
    });
    return toIrradiance(sums, q, radius);
}

std::vector<Vec3f> detpFlannCandidates(const Scene& scene, const RayCache& cache, float radius,
                                       const std::vector<uint32_t>& vertexOrder) {
    const PowerQuantizer q(cache.maxPhotonPower);
    const ImpactIndex index(cache);
    VertexSums sums(scene.vertexCount());
    const float searchRadius = radius * (1 + kFlannCandidateMargin);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertexOrder.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<size_t> candidates;
        std::vector<float> d2;
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const uint32_t v = vertexOrder[i];
            index.withinRadius(scene.positions[v], searchRadius * searchRadius, candidates, d2);
            for (size_t c : candidates) {
                const Segment& s = cache.segments[index.segment(c)];
                if (segmentCrossesDisc(s, scene.positions[v], scene.normals[v], radius)) sums[v].add(s.power, q);
            }
        }
    });
    return toIrradiance(sums, q, radius);
}

std::vector<uint32_t> segmentMortonOrder(const RayCache& cache) {
    // Most discs a segment crosses sit around its end (the surface it hits), so segments are
    // ordered by where they end.
    std::vector<Vec3f> ends(cache.segments.size());
    for (size_t i = 0; i < cache.segments.size(); ++i) ends[i] = cache.segments[i].impactPoint();
    return mortonOrder(ends);
}

}  // namespace qsgi
