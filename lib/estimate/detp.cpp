#include "estimate/detp.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "estimate/fixed_point_power.h"
#include "estimate/impact_index.h"
#include "estimate/morton_order.h"
#include "util/symmetric3.h"

namespace qsgi {

namespace {
// The disc of a vertex when no regions were computed (the paper rule needs none).
const VertexDisc kPaperDisc = [] {
    VertexDisc d;
    d.fallback = true;
    return d;
}();

const VertexDisc& discOf(const DiscRegions* regions, size_t v) { return regions ? (*regions)[v] : kPaperDisc; }

// The published rule applies: chosen, or the vertex has no own surface.
bool usesPaperRule(DetpBoundary rule, const VertexDisc& disc) { return rule == DetpBoundary::Paper || disc.fallback; }

// The segment crosses no disc: it is an emission segment, and only what arrives after the first
// bounce is estimated (direct light is computed apart).
bool leftOut(const Segment& s, bool afterFirstBounce) { return afterFirstBounce && !s.scattered; }
}  // namespace

Reach detpCrossing(const Segment& s, const Vec3f& centre, const Vec3f& normal, const VertexDisc& disc, float radius,
                   DetpBoundary rule, DiscCrossing& where) {
    constexpr Reach kNo = Reach::No;
    const Vec3d d(s.direction), n(normal), o(s.origin), v(centre);
    const double dn = dot(d, n);
    if (!(dn < 0)) return kNo;  // front side only
    const double tStar = dot(v - o, n) / dn;
    if (!(tStar > 0)) return kNo;
    const bool paper = usesPaperRule(rule, disc);
    if (paper) {
        if (!(tStar <= double(s.length) + double(radius))) return kNo;
    } else if (s.hasImpact()) {
        // The impact lies at most ε⁺ in front of the plane; the cap bounds grazing segments.
        if (!(tStar <= double(s.length) + std::min(double(disc.epsAbove) / -dn, double(radius)))) return kNo;
    }
    const Vec3d offset = o + d * tStar - v;
    const double r = radius;
    if (!(dot(offset, offset) <= r * r)) return kNo;
    if (paper) return Reach::Yes;
    where.x = dot(offset, Vec3d(disc.tangent)) / r;
    where.y = dot(offset, Vec3d(disc.bitangent)) / r;
    where.cell = discCellOf(where.x, where.y);
    return reachInCell(disc, where.cell);
}

bool detpCounts(const Segment& s, const Vec3f& centre, const Vec3f& normal, const VertexDisc& disc, float radius,
                DetpBoundary rule, const SceneBvh* bvh, DiscCrossing& where) {
    const Reach reach = detpCrossing(s, centre, normal, disc, radius, rule, where);
    return pointReachable(reach, disc, centre, normal, radius, where.x, where.y, bvh);
}

namespace {
// Fixed-point scale of the crossing coordinates in the `linear` moments.
constexpr double kMomentScale = 1048576.0;  // 2^20
// Above this the reachable region is too thin for a linear fit to be trusted (docs/design.md §5).
constexpr double kMaxFitCondition = 1e4;
}  // namespace

int32_t DetpVertexSums::momentOf(double coordinate) { return int32_t(std::llround(coordinate * kMomentScale)); }

void DetpVertexSums::add(const Vec3f& phi, const DiscCrossing& at, const PowerQuantizer& q, bool moments, int sign) {
    add(phi, moments ? momentOf(at.x) : 0, moments ? momentOf(at.y) : 0, q, moments, sign);
}

void DetpVertexSums::add(const Vec3f& phi, int32_t qx, int32_t qy, const PowerQuantizer& q, bool moments, int sign) {
    if (sign > 0) power.add(phi, q);
    else power.subtract(phi, q);
    if (!moments) return;
    for (int c = 0; c < 3; ++c) {
        const int64_t p = sign * q.quantize(phi[c]);
        x[c] += Int128(p) * qx;
        y[c] += Int128(p) * qy;
    }
}

DetpVertexSums& DetpVertexSums::operator+=(const DetpVertexSums& o) {
    power += o.power;
    for (int c = 0; c < 3; ++c) {
        x[c] += o.x[c];
        y[c] += o.y[c];
    }
    return *this;
}

DetpVertexSums& DetpVertexSums::operator-=(const DetpVertexSums& o) {
    power.r -= o.power.r, power.g -= o.power.g, power.b -= o.power.b;
    for (int c = 0; c < 3; ++c) {
        x[c] -= o.x[c];
        y[c] -= o.y[c];
    }
    return *this;
}

bool DetpVertexSums::operator==(const DetpVertexSums& o) const {
    bool same = power.r == o.power.r && power.g == o.power.g && power.b == o.power.b;
    for (int c = 0; c < 3; ++c) same = same && x[c] == o.x[c] && y[c] == o.y[c];
    return same;
}

Vec3f detpVertexIrradiance(const DetpVertexSums& sums, const VertexDisc* discOrNull, float radius, DetpBoundary rule,
                           const PowerQuantizer& q) {
    const VertexDisc& disc = discOrNull ? *discOrNull : kPaperDisc;
    const double r2 = double(radius) * double(radius);
    const Vec3d flux = sums.power.watts(q);
    if (usesPaperRule(rule, disc)) return Vec3f(flux / (M_PI * r2));
    if (!(disc.reachableArea > 0)) return Vec3f(0.0f);  // buried in geometry
    const double area = M_PI * r2 * double(disc.reachableArea);
    const Vec3d clip = flux / area;
    if (rule == DetpBoundary::Clip || disc.reachable.count() == kDiscCells) return Vec3f(clip);
    // Linear: least squares of a + b·x + c·y against the crossings over the reachable cells
    // (unit-disc coordinates). Normal equations M (a, b, c) = (Σ Φ, Σ Φx, Σ Φy).
    Symmetric3 m{};
    for (int c = 0; c < kDiscCells; ++c) {
        const double w = disc.cellShare(c);  // a mixed cell by its reachable share
        if (w == 0) continue;
        const CellMoments& k = discCellMoments(c);
        m[0][0] += w * k.m0, m[0][1] += w * k.mx, m[0][2] += w * k.my;
        m[1][1] += w * k.mxx, m[1][2] += w * k.mxy, m[2][2] += w * k.myy;
    }
    m[1][0] = m[0][1], m[2][0] = m[0][2], m[2][1] = m[1][2];
    if (!(conditionNumber(m) <= kMaxFitCondition)) return Vec3f(clip);
    const auto w = inverseFirstRow(m);
    Vec3d out;
    for (int c = 0; c < 3; ++c) {
        const double s0 = flux[c], sx = double(sums.x[c]) / kMomentScale * q.quantum(),
                     sy = double(sums.y[c]) / kMomentScale * q.quantum();
        const double a = (w[0] * s0 + w[1] * sx + w[2] * sy) / r2;  // density per unit area at v
        out[c] = a >= 0 ? a : clip[c];
    }
    return Vec3f(out);
}

namespace {

using VertexSums = std::vector<DetpVertexSums>;

std::vector<Vec3f> toIrradiance(const VertexSums& sums, const DiscRegions* regions, float radius, DetpBoundary rule,
                                const PowerQuantizer& q) {
    std::vector<Vec3f> out(sums.size());
    for (size_t v = 0; v < sums.size(); ++v)
        out[v] = detpVertexIrradiance(sums[v], regions ? &(*regions)[v] : nullptr, radius, rule, q);
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

struct CrossedDisc {
    uint32_t vertex;
    DiscCrossing at;
    Reach reach;  // TestPoint (a mixed cell) is decided after the traversal
    bool operator<(const CrossedDisc& o) const { return vertex < o.vertex; }
};

// What the Embree filter needs to apply the exact test, passed through the intersect context.
struct DiscQueryContext {
    RTCIntersectContext base;  // first member: Embree hands back a pointer to it
    const Segment* segment;
    const Scene* scene;
    const DiscRegions* regions;
    float radius;
    DetpBoundary rule;
    std::vector<CrossedDisc>* crossed;
};

void recordCrossedDisc(const RTCFilterFunctionNArguments* args) {
    auto* ctx = reinterpret_cast<DiscQueryContext*>(args->context);
    const auto* vertexOf = static_cast<const uint32_t*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const uint32_t v = vertexOf[RTCHitN_primID(args->hit, args->N, i)];
        DiscCrossing at;
        const Reach reach = detpCrossing(*ctx->segment, ctx->scene->positions[v], ctx->scene->normals[v],
                                         discOf(ctx->regions, v), ctx->radius, ctx->rule, at);
        if (reach != Reach::No) ctx->crossed->push_back({v, at, reach});
        args->valid[i] = 0;  // reject, so traversal goes on to every other disc along the ray
    }
}

}  // namespace

struct DetpDiscs::Crossed : CrossedDisc {};

DetpDiscs::DetpDiscs(const EmbreeDevice& device, const Scene& scene, float radius, DetpBoundary rule,
                     const DiscRegions* regions, const SceneBvh* bvh, const std::vector<uint8_t>* refitted,
                     bool afterFirstBounce)
    : device_(device), scene_(scene), radius_(radius), rule_(rule), regions_(regions), bvh_(bvh),
      afterFirstBounce_(afterFirstBounce), refitted_(refitted ? *refitted : scene.vertexDynamic), staticDiscs_(device),
      dynamicDiscs_(device) {
    refitted_.resize(scene.vertexCount(), 0);
    const float eps = scene.sceneEpsilon();
    rayExtension_ = 1e-4f * radius + eps;
    // Enlarged discs make Embree's float test a superset of the exact one; the filter decides.
    searchRadius_ = radius * (1 + 1e-3f) + eps;
    // Every disc lies within r of a vertex, and every vertex inside the animation's bounds.
    escapeBounds_ = scene.animationBounds.expanded(radius + 2 * rayExtension_);
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) (refitted_[v] ? dynamic_ : static_).vertices.push_back(v);
    addPart(device, staticDiscs_.get(), static_, RTC_BUILD_QUALITY_HIGH);
    addPart(device, dynamicDiscs_.get(), dynamic_, RTC_BUILD_QUALITY_REFIT);
    device.checkError("building the DETP disc BVH");
}

void DetpDiscs::addPart(const EmbreeDevice& device, RTCScene target, Part& part, RTCBuildQuality quality) const {
    rtcSetSceneFlags(target, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(target, quality == RTC_BUILD_QUALITY_HIGH ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM);
    if (!part.vertices.empty()) {
        const size_t n = part.vertices.size();
        RTCGeometry geom = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
        rtcSetGeometryBuildQuality(geom, quality);
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), n);
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), n);
        device.checkError("allocating DETP disc buffers");
        fillPart(geom, part);
        rtcSetGeometryUserData(geom, part.vertices.data());
        rtcSetGeometryIntersectFilterFunction(geom, recordCrossedDisc);
        rtcCommitGeometry(geom);
        part.geomId = rtcAttachGeometry(target, geom);
        rtcReleaseGeometry(geom);
    }
    rtcCommitScene(target);
}

void DetpDiscs::fillPart(RTCGeometry geom, const Part& part) const {
    auto* vertex = static_cast<float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
    auto* normal = static_cast<float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_NORMAL, 0));
    for (size_t i = 0; i < part.vertices.size(); ++i) {
        const Vec3f& p = scene_.positions[part.vertices[i]];
        const Vec3f& n = scene_.normals[part.vertices[i]];
        vertex[4 * i] = p.x, vertex[4 * i + 1] = p.y, vertex[4 * i + 2] = p.z, vertex[4 * i + 3] = searchRadius_;
        normal[3 * i] = n.x, normal[3 * i + 1] = n.y, normal[3 * i + 2] = n.z;
    }
}

void DetpDiscs::updateDynamic() {
    if (dynamic_.geomId == RTC_INVALID_GEOMETRY_ID) return;
    RTCGeometry geom = rtcGetGeometry(dynamicDiscs_.get(), dynamic_.geomId);
    fillPart(geom, dynamic_);
    rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_NORMAL, 0);
    rtcCommitGeometry(geom);
    rtcCommitScene(dynamicDiscs_.get());
}

void DetpDiscs::crossings(const Segment& s, std::vector<Crossed>& out) const {
    crossingsIn(s, {{staticDiscs_.get(), &static_}, {dynamicDiscs_.get(), &dynamic_}}, out);
}

void DetpDiscs::crossingsIn(const Segment& s, std::initializer_list<std::pair<RTCScene, const Part*>> bvhs,
                            std::vector<Crossed>& out) const {
    // Every query (sums, findCrossings, recompute) comes through here: the one place to leave a
    // segment out, which keeps the callers' segment indexes as they are.
    if (leftOut(s, afterFirstBounce_)) {
        out.clear();
        return;
    }
    // Per thread and reused: an allocation per segment cost as much as a small BVH's traversal.
    thread_local std::vector<CrossedDisc> crossed;
    crossed.clear();
    DiscQueryContext ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.segment = &s;
    ctx.scene = &scene_;
    ctx.regions = regions_;
    ctx.radius = radius_;
    ctx.rule = rule_;
    ctx.crossed = &crossed;
    // Start a little before the segment and end a little past the farthest point any rule can
    // count: t + r for an impact, past the padded bounds for an escaping photon.
    const float slack = rayExtension_;
    float end = s.length + radius_;
    if (!s.hasImpact()) end = std::max(end, escapeBounds_.exitDistance(s.origin, s.direction));
    const Vec3f o = s.origin - s.direction * slack;
    for (const auto& [bvh, part] : bvhs) {
        if (part->geomId == RTC_INVALID_GEOMETRY_ID) continue;
        RTCRayHit rh;
        rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
        rh.ray.dir_x = s.direction.x; rh.ray.dir_y = s.direction.y; rh.ray.dir_z = s.direction.z;
        rh.ray.tnear = 0;
        rh.ray.tfar = end + 2 * slack;
        rh.ray.time = 0;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(bvh, &ctx.base, &rh);
    }
    // Embree may report a primitive more than once along one ray (a filter function sees a
    // primitive once per BVH leaf that holds it, and spatial splits put one in several leaves).
    std::sort(crossed.begin(), crossed.end());
    crossed.erase(std::unique(crossed.begin(), crossed.end(),
                              [](const CrossedDisc& a, const CrossedDisc& b) { return a.vertex == b.vertex; }),
                  crossed.end());
    out.clear();
    for (const CrossedDisc& c : crossed)
        if (pointReachable(c.reach, discOf(regions_, c.vertex), scene_.positions[c.vertex], scene_.normals[c.vertex], radius_,
                           c.at.x, c.at.y, bvh_))
            out.push_back(Crossed{c});
}

void DetpDiscs::recompute(const std::vector<const Segment*>& segments, const PowerQuantizer& q,
                          const std::vector<uint32_t>& vertices, std::vector<DetpVertexSums>& sums) const {
    for (uint32_t v : vertices) sums[v] = DetpVertexSums();
    if (vertices.empty() || segments.empty()) return;
    EmbreeScene bvh(device_);
    Part part;
    part.vertices = vertices;
    addPart(device_, bvh.get(), part, RTC_BUILD_QUALITY_MEDIUM);
    // Crossings are found in parallel and applied in one thread, in segment order: integer sums
    // make the order irrelevant to the bits, and few vertices are recomputed.
    constexpr size_t kChunk = 256;
    const size_t chunks = (segments.size() + kChunk - 1) / kChunk;
    struct Hit {
        uint32_t segment;
        CrossedDisc at;
    };
    std::vector<std::vector<Hit>> found(chunks);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<Crossed> crossed;
        for (size_t c = r.begin(); c != r.end(); ++c)
            for (size_t i = c * kChunk; i < std::min(segments.size(), (c + 1) * kChunk); ++i) {
                crossingsIn(*segments[i], {{bvh.get(), &part}}, crossed);
                for (const Crossed& x : crossed) found[c].push_back({uint32_t(i), x});
            }
    });
    const bool moments = rule_ == DetpBoundary::Linear;
    for (const auto& hits : found)
        for (const Hit& h : hits) sums[h.at.vertex].add(segments[h.segment]->power, h.at.at, q, moments);
}

std::vector<DetpVertexSums> DetpDiscs::sums(const std::vector<Segment>& segments, const PowerQuantizer& q,
                                            DetpQueryStats* stats) const {
    tbb::enumerable_thread_specific<VertexSums> perThread([&] { return VertexSums(scene_.vertexCount()); });
    tbb::enumerable_thread_specific<uint64_t> hitCount(0);
    addCrossings(segments, q, perThread, hitCount);
    if (stats)
        for (uint64_t h : hitCount) stats->discHits += h;
    return combine(perThread, scene_.vertexCount());
}

std::vector<DetpVertexSums> DetpDiscs::sums(const RayCache& cache, bool morton, const PowerQuantizer& q,
                                            DetpQueryStats* stats, WorkCounter* progress) const {
    if (progress) progress->setTotal(cache.segmentCount());
    tbb::enumerable_thread_specific<VertexSums> perThread([&] { return VertexSums(scene_.vertexCount()); });
    tbb::enumerable_thread_specific<uint64_t> hitCount(0);
    // Group after group of whole blocks, each decoded and put in order on its own: memory stays
    // at one group's segments whatever the photon count. Ordered in groups of 2^18 segments the
    // pass runs as fast as ordered whole (data/cornell, 10^6 photons, r = 50 mm: 1.24 s with
    // groups of 2^21, 1.26 s with 2^17).
    constexpr uint64_t kGroupSegments = uint64_t(1) << 18;
    for (size_t begin = 0; begin < cache.blockCount();) {
        size_t end = begin + 1;
        const uint64_t first = cache.blockFirstSegment(begin);
        while (end < cache.blockCount() && cache.blockFirstSegment(end) - first < kGroupSegments) ++end;
        addCrossings(segmentsInQueryOrder(cache, begin, end, morton), q, perThread, hitCount, progress);
        begin = end;
    }
    if (stats)
        for (uint64_t h : hitCount) stats->discHits += h;
    return combine(perThread, scene_.vertexCount());
}

void DetpDiscs::addCrossings(const std::vector<Segment>& segments, const PowerQuantizer& q,
                             tbb::enumerable_thread_specific<std::vector<DetpVertexSums>>& perThread,
                             tbb::enumerable_thread_specific<uint64_t>& hitCount, WorkCounter* progress) const {
    const bool moments = rule_ == DetpBoundary::Linear;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, segments.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        VertexSums& sums = perThread.local();
        uint64_t& hits = hitCount.local();
        std::vector<Crossed> crossed;
        for (size_t i = r.begin(); i != r.end(); ++i) {
            crossings(segments[i], crossed);
            for (const Crossed& c : crossed) sums[c.vertex].add(segments[i].power, c.at, q, moments);
            hits += crossed.size();
        }
        if (progress) progress->add(r.size());
    });
}

void DetpDiscs::findCrossings(const std::vector<Segment>& segments, Discs which, std::vector<SegmentCrossing>& out) const {
    // Fixed chunks, concatenated in order: the list does not depend on the schedule.
    constexpr size_t kChunk = 256;
    const size_t chunks = (segments.size() + kChunk - 1) / kChunk;
    std::vector<std::vector<SegmentCrossing>> found(chunks);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<Crossed> crossed;
        for (size_t c = r.begin(); c != r.end(); ++c)
            for (size_t i = c * kChunk; i < std::min(segments.size(), (c + 1) * kChunk); ++i) {
                if (which == Discs::Refitted) crossingsIn(segments[i], {{dynamicDiscs_.get(), &dynamic_}}, crossed);
                else if (which == Discs::Fixed) crossingsIn(segments[i], {{staticDiscs_.get(), &static_}}, crossed);
                else crossings(segments[i], crossed);
                for (const Crossed& x : crossed) found[c].push_back({uint32_t(i), x.vertex, x.at});
            }
    });
    out.clear();
    size_t total = 0;
    for (const auto& f : found) total += f.size();
    out.reserve(total);
    for (const auto& f : found) out.insert(out.end(), f.begin(), f.end());
}

DetpVertexSums detpVertexSums(const Scene& scene, uint32_t v, const std::vector<const Segment*>& segments, float radius,
                              DetpBoundary rule, const DiscRegions* regions, const SceneBvh* bvh, const PowerQuantizer& q,
                              bool afterFirstBounce) {
    DetpVertexSums sums;
    const VertexDisc& disc = discOf(regions, v);
    DiscCrossing at;
    for (const Segment* s : segments)
        if (!leftOut(*s, afterFirstBounce) && detpCounts(*s, scene.positions[v], scene.normals[v], disc, radius, rule, bvh, at))
            sums.add(s->power, at, q, rule == DetpBoundary::Linear);
    return sums;
}

std::vector<Vec3f> detpBruteForce(const Scene& scene, const RayCache& cache, float radius, DetpBoundary rule,
                                  const DiscRegions* regions, const SceneBvh* bvh, bool afterFirstBounce) {
    const PowerQuantizer q(cache.maxPhotonPower);
    std::vector<Segment> segments = cache.decodeAll();
    // Nothing indexes these segments: the left-out ones can go.
    if (afterFirstBounce)
        segments.erase(std::remove_if(segments.begin(), segments.end(), [](const Segment& s) { return leftOut(s, true); }),
                       segments.end());
    const bool moments = rule == DetpBoundary::Linear;
    VertexSums sums(scene.vertexCount());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, scene.vertexCount(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t v = r.begin(); v != r.end(); ++v) {
            const VertexDisc& disc = discOf(regions, v);
            DiscCrossing at;
            for (const Segment& s : segments)
                if (detpCounts(s, scene.positions[v], scene.normals[v], disc, radius, rule, bvh, at))
                    sums[v].add(s.power, at, q, moments);
        }
    });
    return toIrradiance(sums, regions, radius, rule, q);
}

std::vector<Vec3f> detpFlannCandidates(const Scene& scene, const RayCache& cache, float radius, DetpBoundary rule,
                                       const DiscRegions* regions, const SceneBvh* bvh,
                                       const std::vector<uint32_t>& vertexOrder, bool afterFirstBounce) {
    const PowerQuantizer q(cache.maxPhotonPower);
    const bool moments = rule == DetpBoundary::Linear;
    const std::vector<Segment> segments = cache.decodeAll();
    const ImpactIndex index(segments, afterFirstBounce);
    VertexSums sums(scene.vertexCount());
    const float searchRadius = radius * (1 + kFlannCandidateMargin);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertexOrder.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<size_t> candidates;
        std::vector<float> d2;
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const uint32_t v = vertexOrder[i];
            const VertexDisc& disc = discOf(regions, v);
            index.withinRadius(scene.positions[v], searchRadius * searchRadius, candidates, d2);
            DiscCrossing at;
            for (size_t c : candidates) {
                const Segment& s = segments[index.segment(c)];
                if (detpCounts(s, scene.positions[v], scene.normals[v], disc, radius, rule, bvh, at))
                    sums[v].add(s.power, at, q, moments);
            }
        }
    });
    return toIrradiance(sums, regions, radius, rule, q);
}

std::vector<Segment> segmentsInQueryOrder(const RayCache& cache, size_t beginBlock, size_t endBlock, bool morton) {
    std::vector<Segment> decoded = cache.decodeBlocks(beginBlock, endBlock);
    if (!morton) return decoded;
    std::vector<Vec3f> ends(decoded.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, decoded.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) ends[i] = decoded[i].impactPoint();
    });
    const std::vector<uint32_t> order = mortonOrder(ends);
    std::vector<Segment> ordered(decoded.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, order.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) ordered[i] = decoded[order[i]];
    });
    return ordered;
}

}  // namespace qsgi
