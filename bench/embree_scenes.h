// Embree scenes holding every triangle of a Scene in one geometry, for the ceilings the
// benchmarks read our tracing against: configured as SceneBvh configures its parts (robust
// traversal, build quality high, the tie filter), or raw (build quality high, nothing else:
// Embree's own pace). Owned, released on destruction.
#pragma once

#include <embree3/rtcore.h>

#include "scene/scene.h"
#include "trace/embree_device.h"
#include "trace/scene_bvh.h"

namespace qsgi {

class WholeEmbreeScene {
public:
    // RobustOnly: the robust flag without the filter, to tell their costs apart.
    enum class Config { AsSceneBvh, RobustOnly, Raw };
    WholeEmbreeScene(const EmbreeDevice& device, const Scene& scene, Config config) : scene_(rtcNewScene(device.get())) {
        if (config != Config::Raw) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
        RTCGeometry geometry = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_HIGH);
        if (config == Config::AsSceneBvh) rtcSetGeometryIntersectFilterFunction(geometry, lowestPrimitiveOnTies);
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                     3 * sizeof(float), scene.positions.size()));
        for (size_t v = 0; v < scene.positions.size(); ++v)
            for (int c = 0; c < 3; ++c) vertices[3 * v + size_t(c)] = scene.positions[v][c];
        auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                       3 * sizeof(uint32_t), scene.triangles.size()));
        for (size_t t = 0; t < scene.triangles.size(); ++t)
            for (int c = 0; c < 3; ++c) indices[3 * t + size_t(c)] = scene.triangles[t].v[c];
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene_, geometry);
        rtcReleaseGeometry(geometry);
        rtcCommitScene(scene_);
        device.checkError("building a benchmark's Embree scene");
    }
    ~WholeEmbreeScene() { rtcReleaseScene(scene_); }
    WholeEmbreeScene(const WholeEmbreeScene&) = delete;
    WholeEmbreeScene& operator=(const WholeEmbreeScene&) = delete;
    RTCScene get() const { return scene_; }

private:
    RTCScene scene_;
};

}  // namespace qsgi
