#include "trace/scene_bvh.h"

#include <limits>
#include <unordered_map>

namespace qsgi {

SceneBvh::SceneBvh(const EmbreeDevice& device, const Scene& scene)
    : device_(device), all_(device), dynamicOnly_(device) {
    rtcSetSceneBuildQuality(all_.get(), RTC_BUILD_QUALITY_HIGH);
    // Robust traversal never culls a box that a ray touches: whether a ray grazing a surface at
    // the scene epsilon (the disc regions' tests) hits must not depend on the BVH's layout, which
    // changes whenever something moves.
    rtcSetSceneFlags(all_.get(), RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneFlags(dynamicOnly_.get(), RTC_SCENE_FLAG_ROBUST);
    static_ = addPart(all_.get(), scene, false, RTC_BUILD_QUALITY_HIGH);
    dynamic_ = addPart(all_.get(), scene, true, RTC_BUILD_QUALITY_REFIT);
    dynamicAlone_ = addPart(dynamicOnly_.get(), scene, true, RTC_BUILD_QUALITY_REFIT);
    rtcCommitScene(all_.get());
    rtcCommitScene(dynamicOnly_.get());
    device_.checkError("building the scene BVH");
    // Positions are re-centred on the scene (Scene::worldOrigin), so the coordinate magnitude is
    // bounded by the extent; float spacing at the extent is ~1e-7 of it, and 1e-5 leaves margin.
    const Bounds3f b = scene.animationBounds;
    rayEpsilon_ = std::max(1e-5f * b.extent(), 64 * std::numeric_limits<float>::epsilon() * b.maxAbsCoordinate());
    if (!(rayEpsilon_ > 0)) rayEpsilon_ = 1e-5f;
}

SceneBvh::Part SceneBvh::addPart(RTCScene target, const Scene& scene, bool dynamic, RTCBuildQuality quality) {
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
    rtcCommitGeometry(geom);
    part.geomId = rtcAttachGeometry(target, geom);
    rtcReleaseGeometry(geom);  // the scene holds its own reference
    return part;
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
    for (auto [target, part] : {std::pair{all_.get(), &dynamic_}, std::pair{dynamicOnly_.get(), &dynamicAlone_}}) {
        if (part->geomId == RTC_INVALID_GEOMETRY_ID) continue;
        RTCGeometry geom = rtcGetGeometry(target, part->geomId);
        fillVertices(geom, *part, scene);
        rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
        rtcCommitGeometry(geom);
        rtcCommitScene(target);
    }
    device_.checkError("refitting dynamic geometry");
}

namespace {
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
}  // namespace

std::optional<SurfaceHit> SceneBvh::intersect(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh = makeRay(origin, direction, tnear, tfar);
    rtcIntersect1(all_.get(), &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    const Part& part = rh.hit.geomID == static_.geomId ? static_ : dynamic_;
    return SurfaceHit{rh.ray.tfar, part.triangles[rh.hit.primID], rh.hit.u, rh.hit.v};
}

bool SceneBvh::occluded(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray = makeRay(origin, direction, tnear, tfar).ray;
    rtcOccluded1(all_.get(), &context, &ray);
    return ray.tfar < 0;  // Embree sets tfar to -inf on a hit
}

bool SceneBvh::dynamicOccludes(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const {
    if (dynamicAlone_.geomId == RTC_INVALID_GEOMETRY_ID) return false;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray = makeRay(origin, direction, tnear, tfar).ray;
    rtcOccluded1(dynamicOnly_.get(), &context, &ray);
    return ray.tfar < 0;  // Embree sets tfar to -inf on a hit
}

}  // namespace qsgi
