#include "trace/scene_bvh.h"

#include "trace/counter_rng.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>

namespace qsgi {

// Embree accepts a candidate at t equal to the current closest (and hands the filter the
// candidate's t as the ray's tfar), so without this the winner of a tie would be whichever
// triangle traversal met last. With it, equal t goes to the lowest primitive id; primitive ids
// follow scene triangle ids within a part, so this is "lowest triangle id".
void lowestPrimitiveOnTies(const RTCFilterFunctionNArguments* args) {
    auto* ctx = reinterpret_cast<TieBreakContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
        const float t = RTCRayN_tfar(args->ray, args->N, i);
        if (t == ctx->bestT && ctx->bestPrim != RTC_INVALID_GEOMETRY_ID && prim > ctx->bestPrim) {
            args->valid[i] = 0;
            continue;
        }
        ctx->bestT = t;
        ctx->bestPrim = prim;
    }
}

float rayChoice(const Vec3f& origin, const Vec3f& direction, uint32_t triangle, RayChoice purpose) {
    auto bits = [](float x) {
        uint32_t b;
        std::memcpy(&b, &x, sizeof b);
        return uint64_t(b);
    };
    uint64_t h = mix64(bits(origin.x) << 32 | bits(origin.y));
    h = mix64(h ^ (bits(origin.z) << 32 | bits(direction.x)));
    h = mix64(h ^ (bits(direction.y) << 32 | bits(direction.z)));
    h = mix64(h ^ triangle ^ uint64_t(purpose));
    return float(h >> 40) * 0x1p-24f;
}

namespace {

// Drops the hits where the surface lets the ray through (PassThrough); true if lane i survives.
// blendStops: BLEND surfaces stop it (transmittance() weighs them itself).
Vec3f rayDirection(const RTCFilterFunctionNArguments* args, unsigned i) {
    return Vec3f(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i), RTCRayN_dir_z(args->ray, args->N, i));
}

bool stopsRay(const RTCFilterFunctionNArguments* args, unsigned i, bool blendStops) {
    const auto* pass = static_cast<const PassThrough*>(args->geometryUserPtr);
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    const uint32_t triangle = pass->sceneTriangle[prim];
    if (!pass->frontAlongNg.empty() && pass->frontAlongNg[prim] != 0) {
        // One of a two-sided pair: the ray meets the one whose front faces it (at exactly
        // grazing incidence both, and the tie rule picks).
        const Vec3f ng(RTCHitN_Ng_x(args->hit, args->N, i), RTCHitN_Ng_y(args->hit, args->N, i),
                       RTCHitN_Ng_z(args->hit, args->N, i));
        if (float(pass->frontAlongNg[prim]) * dot(rayDirection(args, i), ng) > 0) return false;
    }
    if (!pass->lookup->letsLightThrough(triangle) || (blendStops && pass->lookup->blends(triangle))) return true;
    const Vec3f origin(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                       RTCRayN_org_z(args->ray, args->N, i));
    const Vec3f direction = rayDirection(args, i);
    return pass->lookup->stops(triangle, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i),
                               rayChoice(origin, direction, triangle, RayChoice::Blend));
}

// Closest hits through surfaces that let light through: those dropped, then the tie rule.
void passThroughThenLowestPrimitive(const RTCFilterFunctionNArguments* args) {
    const bool blendStops = reinterpret_cast<const TieBreakContext*>(args->context)->blendStops;
    for (unsigned i = 0; i < args->N; ++i)
        if (args->valid[i] != 0 && !stopsRay(args, i, blendStops)) args->valid[i] = 0;
    lowestPrimitiveOnTies(args);
}

// Occlusion through surfaces that let light through.
void passThroughOccluded(const RTCFilterFunctionNArguments* args) {
    for (unsigned i = 0; i < args->N; ++i)
        if (args->valid[i] != 0 && !stopsRay(args, i, false)) args->valid[i] = 0;
}

RTCRayHit makeRay(const Vec3f& o, const Vec3f& d, float tnear, float tfar) {
    RTCRayHit rh;
    rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
    rh.ray.tnear = tnear;
    rh.ray.tfar = tfar;
    rh.ray.time = 0;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

bool occludes(RTCScene scene, const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray = makeRay(origin, direction, tnear, tfar).ray;
    rtcOccluded1(scene, &context, &ray);
    return ray.tfar < 0;  // Embree sets tfar to -inf on a hit
}

// An occlusion query that counts only triangles flagged in `moved` (by scene triangle): a
// deforming mesh's unmoved triangles are dynamic geometry, but they block nothing new.
struct MovedOnlyContext {
    RTCIntersectContext base;  // first member: Embree hands back a pointer to it
    const std::vector<uint8_t>* moved;
    const std::vector<uint32_t>* sceneTriangle;  // primID -> scene triangle
};

void acceptMovedOnly(const RTCFilterFunctionNArguments* args) {
    const auto* ctx = reinterpret_cast<const MovedOnlyContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i)
        if (args->valid[i] != 0 && !(*ctx->moved)[(*ctx->sceneTriangle)[RTCHitN_primID(args->hit, args->N, i)]])
            args->valid[i] = 0;
}

}  // namespace

SceneBvh::SceneBvh(const EmbreeDevice& device, const Scene& scene)
    : device_(device), staticScene_(device), dynamicScene_(device) {
    // Robust traversal never culls a box that a ray touches: whether a ray grazing a surface at
    // the scene epsilon (the disc regions' tests) hits must not depend on a BVH's layout.
    // movedOccludes filters the dynamic part through its context.
    rtcSetSceneFlags(staticScene_.get(), RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneFlags(dynamicScene_.get(), RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(staticScene_.get(), RTC_BUILD_QUALITY_HIGH);
    surfaces_ = std::make_shared<const SurfaceLookup>(scene);
    static_ = addPart(staticScene_.get(), scene, false, RTC_BUILD_QUALITY_HIGH, surfaces_);
    dynamic_ = addPart(dynamicScene_.get(), scene, true, RTC_BUILD_QUALITY_REFIT, surfaces_);
    rtcCommitScene(staticScene_.get());
    rtcCommitScene(dynamicScene_.get());
    device_.checkError("building the scene BVH");
    // Positions are re-centred on the scene (Scene::worldOrigin), so the coordinate magnitude is
    // bounded by the extent; float spacing at the extent is ~1e-7 of it, and 1e-5 leaves margin.
    const Bounds3f b = scene.animationBounds;
    rayEpsilon_ = std::max(1e-5f * b.extent(), 64 * std::numeric_limits<float>::epsilon() * b.maxAbsCoordinate());
    if (!(rayEpsilon_ > 0)) rayEpsilon_ = 1e-5f;
    nearScene_ = b.expanded(b.extent());
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        if (!surfaces_->transmits(t) && !surfaces_->blends(t)) continue;
        if (scene.triangleDynamic[t]) {
            shareBounds_ = nearScene_.expanded(nearScene_.extent());  // wherever it goes
            break;
        }
        for (uint32_t v : scene.triangles[t].v) shareBounds_.extend(scene.positions[v]);
    }
    if (!shareBounds_.empty()) shareBounds_ = shareBounds_.expanded(rayEpsilon_);
    boundDynamic(scene);
}

SceneBvh::Part SceneBvh::addPart(RTCScene target, const Scene& scene, bool dynamic, RTCBuildQuality quality,
                                 const std::shared_ptr<const SurfaceLookup>& lookup) {
    Part part;
    std::unordered_map<uint32_t, uint32_t> remap;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        if (bool(scene.triangleDynamic[t]) != dynamic) continue;
        part.triangles.push_back(t);
        for (uint32_t v : scene.triangles[t].v)
            if (remap.emplace(v, uint32_t(part.vertices.size())).second) part.vertices.push_back(v);
    }
    if (part.triangles.empty()) return part;
    RTCGeometry geom = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geom, quality);
    auto* index = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(uint32_t), part.triangles.size()));
    rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), part.vertices.size());
    device_.checkError("allocating geometry buffers");
    for (size_t i = 0; i < part.triangles.size(); ++i)
        for (int k = 0; k < 3; ++k) index[3 * i + k] = remap[scene.triangles[part.triangles[i]].v[k]];
    fillVertices(geom, part, scene);
    bool passes = false, twoSided = false;
    for (uint32_t t : part.triangles) {
        passes = passes || lookup->letsLightThrough(t);
        twoSided = twoSided || scene.twoSided(t);
    }
    if (passes || twoSided) {
        part.passThrough = std::make_unique<PassThrough>(PassThrough{lookup, part.triangles, {}});
        if (twoSided) orientTwoSided(*part.passThrough, scene);
        rtcSetGeometryUserData(geom, part.passThrough.get());
        rtcSetGeometryIntersectFilterFunction(geom, passThroughThenLowestPrimitive);
        rtcSetGeometryOccludedFilterFunction(geom, passThroughOccluded);
    } else {
        rtcSetGeometryIntersectFilterFunction(geom, lowestPrimitiveOnTies);
    }
    rtcCommitGeometry(geom);
    part.geomId = rtcAttachGeometry(target, geom);
    rtcReleaseGeometry(geom);  // the scene holds its own reference
    return part;
}

void SceneBvh::orientTwoSided(PassThrough& pass, const Scene& scene) {
    pass.frontAlongNg.resize(pass.sceneTriangle.size());
    for (size_t i = 0; i < pass.sceneTriangle.size(); ++i) {
        const uint32_t t = pass.sceneTriangle[i];
        if (!scene.twoSided(t)) continue;
        // Embree's Ng points out of the CCW side, as the geometric normal does; the front is
        // frontFaceNormal's (a skinned mesh may turn it: re-read each pose).
        const Vec3f front = frontFaceNormal(scene.positions, scene.normals, scene.triangles[t]);
        pass.frontAlongNg[i] = dot(scene.geometricNormal(t), front) < 0 ? -1 : 1;
    }
}

void SceneBvh::fillVertices(RTCGeometry geom, const Part& part, const Scene& scene) {
    auto* vertex = static_cast<float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
    for (size_t i = 0; i < part.vertices.size(); ++i) {
        const Vec3f& p = scene.positions[part.vertices[i]];
        vertex[3 * i] = p.x;
        vertex[3 * i + 1] = p.y;
        vertex[3 * i + 2] = p.z;
    }
}

void SceneBvh::updateDynamic(const Scene& scene) {
    if (dynamic_.empty()) return;
    RTCGeometry geom = rtcGetGeometry(dynamicScene_.get(), dynamic_.geomId);
    fillVertices(geom, dynamic_, scene);
    if (dynamic_.passThrough && !dynamic_.passThrough->frontAlongNg.empty()) orientTwoSided(*dynamic_.passThrough, scene);
    rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geom);
    rtcCommitScene(dynamicScene_.get());
    device_.checkError("refitting dynamic geometry");
    boundDynamic(scene);
}

void SceneBvh::boundDynamic(const Scene& scene) {
    dynamicBounds_ = Bounds3f();
    for (uint32_t v : dynamic_.vertices) dynamicBounds_.extend(scene.positions[v]);
    // Far more than a float hit's rounding (the epsilon is ~1e-5 of the scene).
    dynamicBounds_ = dynamicBounds_.expanded(rayEpsilon_);
}

std::optional<SurfaceHit> SceneBvh::intersectPart(const EmbreeScene& embree, const Part& part, const Vec3f& origin,
                                                  const Vec3f& direction, float tnear, float tfar, bool blendStops) const {
    if (part.empty()) return std::nullopt;
    TieBreakContext context;
    rtcInitIntersectContext(&context.base);
    context.blendStops = blendStops;
    RTCRayHit rh = makeRay(origin, direction, tnear, tfar);
    rtcIntersect1(embree.get(), &context.base, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    return SurfaceHit{rh.ray.tfar, part.triangles[rh.hit.primID], rh.hit.u, rh.hit.v,
                      Vec3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z)};
}

std::optional<SurfaceHit> SceneBvh::intersect(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const {
    return closestHit(origin, direction, tnear, tfar, false);
}

std::optional<SurfaceHit> SceneBvh::closestHit(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar,
                                               bool blendStops) const {
    const std::optional<SurfaceHit> still = intersectPart(staticScene_, static_, origin, direction, tnear, tfar, blendStops);
    // The dynamic scene only needs to look as far as the static hit (inclusive: a tie there is
    // decided below by triangle id), and not at all when the ray misses the dynamic triangles'
    // padded bounds over that span, as most rays do (dynamicOccludes' test; a call into Embree
    // saved).
    if (dynamic_.empty()) return still;
    double t0 = tnear, t1 = still ? still->t : tfar;
    if (nearScene_.contains(origin) && !dynamicBounds_.clip(origin, direction, t0, t1)) return still;
    const std::optional<SurfaceHit> moving =
        intersectPart(dynamicScene_, dynamic_, origin, direction, tnear, still ? still->t : tfar, blendStops);
    if (!moving) return still;
    if (!still || moving->t < still->t || (moving->t == still->t && moving->triangle < still->triangle)) return moving;
    return still;
}

std::optional<SurfaceHit> SceneBvh::intersectThroughPanes(const Vec3f& origin, const Vec3f& direction, float tnear,
                                                          float tfar) const {
    std::optional<SurfaceHit> hit = intersect(origin, direction, tnear, tfar);
    for (int pane = 0; hit && surfaces_->transmits(hit->triangle) && pane < kMostPanes; ++pane) {
        if (!(rayChoice(origin, direction, hit->triangle, RayChoice::Pane) < surfaces_->transmission(hit->triangle, hit->u, hit->v)))
            break;
        hit = intersect(origin, direction, std::nextafter(hit->t, std::numeric_limits<float>::infinity()), tfar);
    }
    return hit;
}

Vec3f SceneBvh::transmittance(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const {
    double t0 = tnear, t1 = tfar;
    if (!passesShares() || !shareBounds_.clip(origin, direction, t0, t1))
        return occluded(origin, direction, tnear, tfar) ? Vec3f(0.0f) : Vec3f(1.0f);
    Vec3f through(1.0f);
    float from = tnear;
    for (int crossed = 0; crossed <= kMostPanes; ++crossed) {
        const std::optional<SurfaceHit> hit = closestHit(origin, direction, from, tfar, true);
        if (!hit) return through;
        const uint32_t t = hit->triangle;
        const bool pane = surfaces_->transmits(t), blend = surfaces_->blends(t);
        if ((!pane && !blend) || crossed == kMostPanes) break;
        // A pane passes T of the light, tinted; a BLEND passes 1 − alpha, and its alpha share
        // meets the pane (a surface that is both).
        const Rgba base = surfaces_->baseColour(t, hit->u, hit->v);
        const Vec3f paneShare = pane ? Vec3f(base[0], base[1], base[2]) * surfaces_->transmission(t, hit->u, hit->v) : Vec3f(0.0f);
        through = through * (blend ? Vec3f(1 - base[3]) + paneShare * base[3] : paneShare);
        if (!(maxComponent(through) > 0)) break;
        from = std::nextafter(hit->t, std::numeric_limits<float>::infinity());
    }
    return Vec3f(0.0f);
}

bool SceneBvh::occluded(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const {
    return staticOccludes(origin, direction, tnear, tfar) || dynamicOccludes(origin, direction, tnear, tfar);
}

bool SceneBvh::staticOccludes(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const {
    return !static_.empty() && occludes(staticScene_.get(), origin, direction, tnear, tfar);
}

uint32_t SceneBvh::staticOccludesPacket(const RayPacket& rays) const {
    if (static_.empty() || rays.count == 0) return 0;
    RTCRay16 packet;
    alignas(64) int valid[16];
    for (int i = 0; i < 16; ++i) {
        const bool used = i < rays.count;
        const size_t k = size_t(used ? i : 0);
        valid[i] = used ? -1 : 0;
        packet.org_x[i] = rays.origin[k].x;
        packet.org_y[i] = rays.origin[k].y;
        packet.org_z[i] = rays.origin[k].z;
        packet.dir_x[i] = rays.direction[k].x;
        packet.dir_y[i] = rays.direction[k].y;
        packet.dir_z[i] = rays.direction[k].z;
        packet.tnear[i] = 0.0f;
        packet.tfar[i] = rays.tfar[k];
        packet.time[i] = 0;
        packet.mask[i] = 0xFFFFFFFFu;
        packet.id[i] = 0;
        packet.flags[i] = 0;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcOccluded16(valid, staticScene_.get(), &context, &packet);
    uint32_t blocked = 0;
    for (int i = 0; i < rays.count; ++i)
        if (packet.tfar[i] < 0) blocked |= uint32_t(1) << i;  // Embree sets tfar to -inf on a hit
    return blocked;
}

namespace {
struct NearQuery {
    const uint32_t* index;  // the static geometry's own buffers
    const float* vertex;
    Vec3f centre;
    float radius;
    Vec3d normal;
    double height;
    bool found = false;
    uint32_t visited = 0;
};


// Called for the static triangles whose BVH boxes meet the query ball: one whose own box does,
// with a corner at the query's height or above, ends the search.
bool risesNear(RTCPointQueryFunctionArguments* args) {
    auto* q = static_cast<NearQuery*>(args->userPtr);
    if (q->found) return false;
    if (++q->visited > SceneBvh::kMostTrianglesNear) {
        q->found = true;
        args->query->radius = 0;
        return true;
    }
    Vec3f corners[3];
    for (size_t k = 0; k < 3; ++k) {
        const float* p = q->vertex + 3 * size_t(q->index[3 * size_t(args->primID) + k]);
        corners[k] = Vec3f(p[0], p[1], p[2]);
    }
    if (!triangleRisesNear(corners, q->centre, q->radius, q->normal, q->height)) return false;
    q->found = true;
    args->query->radius = 0;  // nothing more to look for
    return true;
}
}  // namespace

bool triangleRisesNear(const Vec3f corners[3], const Vec3f& centre, float radius, const Vec3d& normal, double height) {
    Bounds3f box;
    double highest = -std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < 3; ++k) {
        box.extend(corners[k]);
        highest = std::max(highest, dot(Vec3d(corners[k]) - Vec3d(centre), normal));
    }
    if (highest < height) return false;
    double squared = 0;
    for (int a = 0; a < 3; ++a) {
        const double below = double(box.lower[a]) - double(centre[a]), above = double(centre[a]) - double(box.upper[a]);
        const double gap = std::max({below, above, 0.0});
        squared += gap * gap;
    }
    return squared <= double(radius) * double(radius);
}

bool SceneBvh::staticGeometryRises(const Vec3f& centre, float radius, const Vec3f& normal, double height) const {
    if (static_.empty()) return false;
    RTCGeometry geom = rtcGetGeometry(staticScene_.get(), static_.geomId);
    NearQuery q{static_cast<const uint32_t*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_INDEX, 0)),
                static_cast<const float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0)), centre, radius,
                Vec3d(normal), height};
    RTCPointQuery query;
    query.x = centre.x;
    query.y = centre.y;
    query.z = centre.z;
    query.radius = radius;
    query.time = 0;
    RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(staticScene_.get(), &query, &context, risesNear, &q);
    return q.found;
}

bool SceneBvh::dynamicOccludes(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const {
    if (dynamic_.empty()) return false;
    double t0 = tnear, t1 = tfar;
    return dynamicBounds_.clip(origin, direction, t0, t1) && occludes(dynamicScene_.get(), origin, direction, tnear, tfar);
}

bool SceneBvh::movedOccludes(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar,
                             const std::vector<uint8_t>& triangleMoved) const {
    if (dynamic_.empty()) return false;
    MovedOnlyContext context;
    rtcInitIntersectContext(&context.base);
    context.base.filter = acceptMovedOnly;
    context.moved = &triangleMoved;
    context.sceneTriangle = &dynamic_.triangles;
    RTCRay ray = makeRay(origin, direction, tnear, tfar).ray;
    rtcOccluded1(dynamicScene_.get(), &context.base, &ray);
    return ray.tfar < 0;
}

}  // namespace qsgi
