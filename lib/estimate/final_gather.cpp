#include "estimate/final_gather.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <cmath>
#include <limits>

#include "estimate/vertex_samples.h"
#include "trace/sampling.h"
#include "util/rounding.h"

namespace qsgi {

namespace {
constexpr float kBarycentricScale = 65535.0f;
uint16_t quantised(float b) { return roundToUint16(std::clamp(b, 0.0f, 1.0f) * kBarycentricScale); }

// Octahedral encoding of a unit direction (Meyer et al. 2010), 16 bits a coordinate, and its
// decoding: the decoded direction is the one cast, whenever the ray is cast.
float signNotZero(float x) { return x < 0 ? -1.0f : 1.0f; }
void encodeOctahedral(const Vec3f& d, uint16_t& u, uint16_t& v) {
    // Any length: the L1 norm divides it out (the gather's directions come unnormalised).
    const float inverseL1 = 1.0f / (std::fabs(d.x) + std::fabs(d.y) + std::fabs(d.z));
    float px = d.x * inverseL1, py = d.y * inverseL1;
    if (d.z < 0) {
        const float qx = (1 - std::fabs(py)) * signNotZero(px), qy = (1 - std::fabs(px)) * signNotZero(py);
        px = qx;
        py = qy;
    }
    u = roundToUint16((std::clamp(px, -1.0f, 1.0f) * 0.5f + 0.5f) * 65535.0f);
    v = roundToUint16((std::clamp(py, -1.0f, 1.0f) * 0.5f + 0.5f) * 65535.0f);
}
// The decoded direction before it is normalised: along the same line.
Vec3f octahedralUnnormalised(uint16_t u, uint16_t v) {
    float px = float(u) / 65535.0f * 2 - 1, py = float(v) / 65535.0f * 2 - 1;
    const float z = 1 - std::fabs(px) - std::fabs(py);
    if (z < 0) {
        const float qx = (1 - std::fabs(py)) * signNotZero(px), qy = (1 - std::fabs(px)) * signNotZero(py);
        px = qx;
        py = qy;
    }
    return Vec3f(px, py, z);
}
Vec3f decodeOctahedral(uint16_t u, uint16_t v) { return normalize(octahedralUnnormalised(u, v)); }
}  // namespace

// A vertex's gather directions: its frame and its numbers, made once for all its rays (the scan
// of a frame's update makes every direction again: they are not stored).
class FinalGather::Directions {
public:
    Directions(const VertexStarts& starts, uint32_t v, uint64_t seed)
        : Directions(VertexSamples(seed, v, VertexStream::Gather), starts.normal(v)) {}
    Directions(const VertexSamples& numbers, const Vec3f& n) : radius_(numbers.dimension(0)), angle_(numbers.dimension(1)), n_(n) {
        orthonormalBasis(n_, t_, b_);
    }
    // Cosine-weighted about n_v (pdf cosθ/π), as cosineHemisphere; of length 1 up to rounding and
    // not normalised: the octahedral encoding it goes to divides by its L1 norm, and the decoded
    // direction cast is normalised once, there.
    Vec3f operator()(uint32_t ray) const {
        const float u0 = radius_.uniform(ray), u1 = angle_.uniform(ray);
        const float r = std::sqrt(u0), phi = 2 * kPi * u1;
        const float z = std::sqrt(std::max(0.0f, 1 - u0));
        return t_ * (r * std::cos(phi)) + b_ * (r * std::sin(phi)) + n_ * z;
    }

private:
    VertexSamples::Dimension radius_, angle_;  // dimensions 0 and 1 of v's points
    Vec3f n_, t_, b_;
};

Vec3f FinalGather::rayDirection(const GatherHit& hit) { return decodeOctahedral(hit.octU, hit.octV); }

namespace {
// The covered-vertex rule on v's cover rays: each meets a back face, or a front face lower above
// v's tangent plane than the start's cover height (VertexStart::coverHeight). The rule is
// geometric: the back side of a doubleSided surface (lib/scene/back_sides.h) is its back face,
// so the inside of a closed doubleSided mesh is covered, as it is without its back sides.
bool coveredBy(const Scene& scene, const GatherHit* hits, uint32_t count, const Vec3f& normal, float coverHeight) {
    if (count == 0) return false;
    for (uint32_t j = 0; j < count; ++j) {
        if (hits[j].triangle == GatherHit::kMiss) return false;
        if (hits[j].triangle == GatherHit::kBackFace || scene.isBackTriangle(hits[j].triangle)) continue;
        const float height = hits[j].t * dot(FinalGather::rayDirection(hits[j]), normal);
        if (!(height < coverHeight)) return false;
    }
    return true;
}
}  // namespace

GatherHit FinalGather::castRay(const SceneBvh& bvh, const std::vector<Vec3f>& frontNormals, const Vec3f& origin,
                               const Vec3f& direction) const {
    GatherHit out;
    // From t = 0: s_v lies a float error off v's own surface (VertexStarts), and a surface
    // beside v (the wall at a floor vertex's foot) lies as near, far nearer than a ray epsilon.
    // Through a pane where the ray's own choice says so (SceneBvh::intersectThroughPanes).
    const auto hit = bvh.intersectThroughPanes(origin, direction, 0.0f, std::numeric_limits<float>::infinity());
    if (!hit) {
        out.t = std::numeric_limits<float>::infinity();
        return out;
    }
    out.t = hit->t;
    out.triangle = dot(direction, frontNormals[hit->triangle]) < 0 ? hit->triangle : GatherHit::kBackFace;
    out.b1 = quantised(hit->u);
    out.b2 = quantised(hit->v);
    return out;
}

void FinalGather::castVertexInto(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                                 const std::vector<Vec3f>& frontNormals, uint32_t v, uint32_t first, uint32_t count,
                                 GatherHit* hits) const {
    if (scene.vertexHidden[v]) {
        for (uint32_t j = 0; j < count; ++j) hits[j] = GatherHit{};
        return;
    }
    const Directions direction(starts, v, seed_);
    const Vec3f origin = starts.point(v);
    // A dark back side casts its cover rays alone (darkBackSide): the rest are left as misses.
    const uint32_t cover = coverRays();
    const bool back = scene.isBackVertex(v) && cover > 0;
    bool dark = back && first >= cover && darkBackSide(scene, starts, v, &probeHits_[size_t(v) * probes_]);
    for (uint32_t j = 0; j < count; ++j) {
        if (dark) {
            hits[j] = GatherHit{};
            continue;
        }
        uint16_t u, w;
        encodeOctahedral(direction(first + j), u, w);
        hits[j] = castRay(bvh, frontNormals, origin, decodeOctahedral(u, w));
        hits[j].octU = u;
        hits[j].octV = w;
        if (back && first == 0 && j + 1 == cover) dark = darkBackSide(scene, starts, v, hits);
    }
}

bool FinalGather::darkBackSide(const Scene& scene, const VertexStarts& starts, uint32_t v, const GatherHit* cover) const {
    return scene.isBackVertex(v) && coveredBy(scene, cover, coverRays(), starts.normal(v), starts.coverHeight(v));
}

std::vector<uint8_t> FinalGather::darkBackSides(const Scene& scene, const VertexStarts& starts,
                                                const std::vector<uint8_t>& covered) const {
    std::vector<uint8_t> dark(scene.vertexCount(), 0);
    if (!scene.backSides || rays_ == 0) return dark;
    for (uint32_t v = uint32_t(scene.frontVertexCount()); v < dark.size(); ++v)
        dark[v] = covered.empty() ? darkBackSide(scene, starts, v, &probeHits_[size_t(v) * probes_]) : covered[v];
    return dark;
}

void FinalGather::castVertex(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                             const std::vector<Vec3f>& frontNormals, uint32_t v) {
    castVertexInto(scene, bvh, starts, frontNormals, v, 0, probes_, &probeHits_[size_t(v) * probes_]);
    if (cached() && restSlot_[v] != kNoSlot)
        castVertexInto(scene, bvh, starts, frontNormals, v, probes_, rays_ - probes_, restOf(v));
}

void FinalGather::clear() {
    probeHits_ = {};
    restHits_ = {};
    restSlot_ = {};
    freeSlots_ = {};
}

void FinalGather::castAll(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, WorkCounter* progress) {
    clear();
    probeHits_.assign(scene.vertexCount() * size_t(probes_), GatherHit{});
    if (cached()) restSlot_.assign(scene.vertexCount(), kNoSlot);
    const std::vector<Vec3f> frontNormals = scene.frontFaceNormals();
    if (progress) progress->setTotal(scene.vertexCount() * uint64_t(rays_));
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(scene.vertexCount()), 16), [&](const tbb::blocked_range<uint32_t>& r) {
        for (uint32_t v = r.begin(); v != r.end(); ++v) castVertex(scene, bvh, starts, frontNormals, v);
        if (progress) progress->add(r.size() * uint64_t(probes_));
    });
    raysCast_ = uint64_t(scene.vertexCount()) * probes_;
}

void FinalGather::cast(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const std::vector<uint32_t>& vertices) {
    if (vertices.empty()) return;
    const std::vector<Vec3f> frontNormals = scene.frontFaceNormals();
    const uint64_t cast = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, vertices.size(), 4), uint64_t(0),
        [&](const tbb::blocked_range<size_t>& r, uint64_t count) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                castVertex(scene, bvh, starts, frontNormals, vertices[i]);
                count += hasAllRays(vertices[i]) ? rays_ : probes_;
            }
            return count;
        },
        [](uint64_t a, uint64_t b) { return a + b; });
    raysCast_ += cast;
}

void FinalGather::setRecords(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const std::vector<uint8_t>& record,
                             WorkCounter* progress) {
    if (!cached()) return;
    // Slots first, in vertex order (which slot a record holds changes no bit: its sum is its own).
    std::vector<uint32_t> added;
    for (uint32_t v = 0; v < record.size(); ++v) {
        if (!record[v] && restSlot_[v] != kNoSlot) {
            freeSlots_.push_back(restSlot_[v]);
            restSlot_[v] = kNoSlot;
        }
    }
    const size_t rest = rays_ - probes_;
    for (uint32_t v = 0; v < record.size(); ++v) {
        if (!record[v] || restSlot_[v] != kNoSlot) continue;
        if (!freeSlots_.empty()) {
            restSlot_[v] = freeSlots_.back();
            freeSlots_.pop_back();
        } else {
            restSlot_[v] = uint32_t(restHits_.size() / rest);
            restHits_.resize(restHits_.size() + rest);
        }
        added.push_back(v);
    }
    const std::vector<Vec3f> frontNormals = scene.frontFaceNormals();
    if (progress) progress->resize(scene.vertexCount() * uint64_t(probes_) + added.size() * rest);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, added.size(), 4), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i)
            castVertexInto(scene, bvh, starts, frontNormals, added[i], probes_, uint32_t(rest), restOf(added[i]));
        if (progress) progress->add(r.size() * rest);
    });
    raysCast_ += uint64_t(added.size()) * rest;
}


std::vector<uint8_t> FinalGather::coveredFromKept(const Scene& scene, const VertexStarts& starts) const {
    std::vector<uint8_t> covered(scene.vertexCount(), 0);
    if (rays_ == 0 || probeHits_.empty()) return covered;
    for (uint32_t v = 0; v < covered.size(); ++v)
        covered[v] = coveredBy(scene, &probeHits_[size_t(v) * probes_], coverRays(), starts.normal(v), starts.coverHeight(v));
    return covered;
}

std::vector<uint8_t> FinalGather::castCovered(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts) const {
    std::vector<uint8_t> covered(scene.vertexCount(), 0);
    if (rays_ == 0) return covered;
    const std::vector<Vec3f> frontNormals = scene.frontFaceNormals();
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(scene.vertexCount()), 64), [&](const tbb::blocked_range<uint32_t>& r) {
        GatherHit hits[kCoverRays];
        for (uint32_t v = r.begin(); v != r.end(); ++v) {
            castVertexInto(scene, bvh, starts, frontNormals, v, 0, coverRays(), hits);
            covered[v] = coveredBy(scene, hits, coverRays(), starts.normal(v), starts.coverHeight(v));
        }
    });
    return covered;
}

namespace {
// A box ahead of a vertex, and the cone from the vertex's start point that holds it: a ray can
// meet the box only if it points into the cone and reaches the box's bounding ball. The test
// needs neither the ray's normalised direction nor a division, and rules out most kept rays
// before the exact one (the scan of every kept ray was two thirds of a later frame's gather on
// data/cornell). The ball is padded far beyond the decoded direction's rounding (a few ulps of
// its length, here 10⁻⁵ of the distance), so no ray the exact test would take is ruled out.
struct BoxAhead {
    const Bounds3f* box;
    Vec3d towards;      // from the start point to the ball's centre
    double nearest;     // how far the ray must reach to enter the ball
    double cosSquared;  // the cone's half-angle, as cos²; -1 with the start point in the ball
    BoxAhead(const Bounds3f* b, const Vec3f& origin) : box(b) {
        const Vec3d centre = (Vec3d(b->lower) + Vec3d(b->upper)) * 0.5;
        towards = centre - Vec3d(origin);
        const double distance = length(towards);
        const double radius = 0.5 * length(Vec3d(b->upper) - Vec3d(b->lower)) + 1e-5 * (distance + 1e-30);
        nearest = distance - radius;
        cosSquared = distance > radius ? (distance * distance - radius * radius) / (distance * distance) : -1.0;
    }
    // Whether the ray along `along` (any length) reaching `t` may meet the box.
    bool mayMeet(const Vec3f& along, float t) const {
        if (cosSquared < 0) return true;
        if (double(t) < nearest) return false;
        const double d = dot(Vec3d(along), towards);
        return d > 0 && d * d >= cosSquared * dot(Vec3d(along), Vec3d(along)) * dot(towards, towards);
    }
};

// Whether the kept ray `hit` (leaving `origin` along its kept direction) meets one of `ahead`.
bool meetsAhead(const Vec3f& origin, const std::vector<BoxAhead>& ahead, const GatherHit& hit) {
    const Vec3f along = octahedralUnnormalised(hit.octU, hit.octV);
    bool mayMeet = false;
    for (const BoxAhead& box : ahead)
        if ((mayMeet = box.mayMeet(along, hit.t))) break;
    if (!mayMeet) return false;
    const Vec3f d = FinalGather::rayDirection(hit);
    for (const BoxAhead& box : ahead) {
        double t0 = 0, t1 = double(hit.t);
        if (box.box->clip(origin, d, t0, t1)) return true;
    }
    return false;
}

bool anyMeetsAhead(const Vec3f& origin, const std::vector<BoxAhead>& ahead, const GatherHit* hits, size_t count) {
    for (size_t j = 0; j < count; ++j)
        if (meetsAhead(origin, ahead, hits[j])) return true;
    return false;
}

// Re-casts the rays of `hits` (leaving `origin`, each along its kept direction) whose segment
// meets one of `ahead`; returns how many.
template <typename Cast>
uint64_t recastSpanMeeting(const Vec3f& origin, const std::vector<BoxAhead>& ahead, GatherHit* hits, size_t count,
                           Cast&& castRay) {
    uint64_t recast = 0;
    for (size_t j = 0; j < count; ++j) {
        if (!meetsAhead(origin, ahead, hits[j])) continue;
        const Vec3f d = FinalGather::rayDirection(hits[j]);
        const uint16_t u = hits[j].octU, w = hits[j].octV;
        hits[j] = castRay(d);
        hits[j].octU = u;
        hits[j].octV = w;
        ++recast;
    }
    return recast;
}
}  // namespace

uint64_t FinalGather::recastMeeting(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                                    const std::vector<Bounds3f>& boxes, const std::vector<uint8_t>& skip) {
    if (boxes.empty() || rays_ == 0) return 0;
    const std::vector<Vec3f> frontNormals = scene.frontFaceNormals();
    const uint64_t recast = tbb::parallel_reduce(
        tbb::blocked_range<uint32_t>(0, uint32_t(scene.vertexCount()), 16), uint64_t(0),
        [&](const tbb::blocked_range<uint32_t>& r, uint64_t count) {
            std::vector<BoxAhead> ahead;
            for (uint32_t v = r.begin(); v != r.end(); ++v) {
                if (skip[v] || scene.vertexHidden[v]) continue;
                const Vec3f origin = starts.point(v);
                const Vec3f& n = starts.normal(v);
                // Every ray leaves into v's hemisphere: a box wholly behind its plane meets none.
                ahead.clear();
                for (const Bounds3f& box : boxes) {
                    float reach = 0;
                    for (int c = 0; c < 8; ++c) {
                        const Vec3f corner((c & 1) ? box.upper.x : box.lower.x, (c & 2) ? box.upper.y : box.lower.y,
                                           (c & 4) ? box.upper.z : box.lower.z);
                        reach = std::max(reach, dot(corner - origin, n));
                    }
                    if (reach >= 0) ahead.emplace_back(&box, origin);
                }
                if (ahead.empty()) continue;
                if (scene.isBackVertex(v)) {
                    // A back side's darkness rests on its cover rays (darkBackSide): one whose rays
                    // meet a mover is cast again whole, as castAll would cast it.
                    const bool rest = cached() && restSlot_[v] != kNoSlot;
                    if (anyMeetsAhead(origin, ahead, &probeHits_[size_t(v) * probes_], probes_) ||
                        (rest && anyMeetsAhead(origin, ahead, restOf(v), rays_ - probes_))) {
                        castVertex(scene, bvh, starts, frontNormals, v);
                        count += rest ? rays_ : probes_;
                    }
                    continue;
                }
                auto recastAlong = [&](const Vec3f& d) { return castRay(bvh, frontNormals, origin, d); };
                count += recastSpanMeeting(origin, ahead, &probeHits_[size_t(v) * probes_], probes_, recastAlong);
                if (cached() && restSlot_[v] != kNoSlot)
                    count += recastSpanMeeting(origin, ahead, restOf(v), rays_ - probes_, recastAlong);
            }
            return count;
        },
        [](uint64_t a, uint64_t b) { return a + b; });
    raysCast_ += recast;
    return recast;
}

Vec3f FinalGather::meanOverHits(const Scene& scene, const FirstPass& firstPass, uint32_t v, const GatherHit* probes,
                                const GatherHit* rest) const {
    // In ray order, in one thread: the same bits for any schedule, and with or without a cache.
    // Misses and back faces add nothing (not even +0).
    const std::vector<Vec3f>& reflected = firstPass.readBy(v);
    const std::vector<Vec3f>* irradiance = firstPass.irradianceReadBy(v);
    Vec3d sum(0.0);
    for (uint32_t j = 0; j < rays_; ++j) {
        const GatherHit& h = j < probes_ ? probes[j] : rest[j - probes_];
        if (h.triangle >= GatherHit::kBackFace) continue;
        const Triangle& tri = scene.triangles[h.triangle];
        const double w1 = double(h.b1) / kBarycentricScale, w2 = double(h.b2) / kBarycentricScale;
        const double w0 = std::max(0.0, 1.0 - w1 - w2);
        // Where the albedo varies, or at a pane or a BLEND: E there times the base colour at the
        // hit (a ray stops at a pane with probability 1 − T, at a BLEND with probability alpha, so
        // it reads ρ E, not the share of it the surface reflects).
        const SurfaceLookup* surfaces = firstPass.surfaces;
        if (irradiance &&
            (surfaces->varies(h.triangle) || surfaces->transmits(h.triangle) || surfaces->blends(h.triangle))) {
            const std::vector<Vec3f>& e = *irradiance;
            const Vec3d arriving = Vec3d(e[tri.v[0]]) * w0 + Vec3d(e[tri.v[1]]) * w1 + Vec3d(e[tri.v[2]]) * w2;
            sum += arriving * Vec3d(firstPass.surfaces->albedo(h.triangle, float(w1), float(w2)));
            continue;
        }
        sum += Vec3d(reflected[tri.v[0]]) * w0 + Vec3d(reflected[tri.v[1]]) * w1 + Vec3d(reflected[tri.v[2]]) * w2;
    }
    return Vec3f(sum / double(rays_));
}

void FinalGather::gather(const Scene& scene, const FirstPass& firstPass, std::vector<Vec3f>& out) const {
    out.assign(scene.vertexCount(), Vec3f(0.0f));
    if (rays_ == 0) return;
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(scene.vertexCount()), 64), [&](const tbb::blocked_range<uint32_t>& r) {
        for (uint32_t v = r.begin(); v != r.end(); ++v) {
            if (!hasAllRays(v)) continue;
            const GatherHit* rest = cached() ? restOf(v) : nullptr;
            out[v] = meanOverHits(scene, firstPass, v, &probeHits_[size_t(v) * probes_], rest);
        }
    });
}

void FinalGather::gather(const Scene& scene, const std::vector<Vec3f>& firstPass, std::vector<Vec3f>& out) const {
    const std::vector<uint8_t> none;
    gather(scene, FirstPass{firstPass, firstPass, none}, out);
}

void FinalGather::castAndGather(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const FirstPass& firstPass,
                                std::vector<Vec3f>& out, WorkCounter* progress) {
    clear();
    out.assign(scene.vertexCount(), Vec3f(0.0f));
    raysCast_ = 0;
    if (rays_ == 0) return;
    const std::vector<Vec3f> frontNormals = scene.frontFaceNormals();
    if (progress) progress->setTotal(scene.vertexCount() * uint64_t(rays_));
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(scene.vertexCount()), 16), [&](const tbb::blocked_range<uint32_t>& r) {
        // One vertex's hits at a time: cast them all, then sum them, as castAll and gather do
        // (summing as each ray returns interleaves the first pass's scattered reads with
        // Embree's, measured 15 % slower on data/cornell refined).
        std::vector<GatherHit> hits(rays_);
        for (uint32_t v = r.begin(); v != r.end(); ++v) {
            if (scene.vertexHidden[v]) continue;  // all misses: 0
            castVertexInto(scene, bvh, starts, frontNormals, v, 0, rays_, hits.data());
            out[v] = meanOverHits(scene, firstPass, v, hits.data(), hits.data() + probes_);
        }
        if (progress) progress->add(r.size() * uint64_t(rays_));
    });
    raysCast_ = uint64_t(scene.vertexCount()) * rays_;
}

}  // namespace qsgi
