// Fuzzes the glTF loader through qsgi's scene building: tinygltf's parser behind our document
// checks, accessor decoding, the node hierarchy, materials, lights and cameras, then what
// RenderJob computes from a scene before tracing (animation bounds, default radius, face
// normals), and, when the file has animations, what --animation gltf does with them: sampling,
// skinning and morphing every frame (at most ~100 frames, whatever the key times), static lights,
// dynamic marking. Only InputError may leave qsgi's code, and no position or normal may be
// non-finite.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "pipeline/render_settings.h"
#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        qsgi::Warnings warnings;
        qsgi::Scene scene = qsgi::loadGltfSceneFromMemory(
            "fuzz.gltf", std::string(reinterpret_cast<const char*>(data), size), "/nonexistent", warnings);
        const qsgi::Animation still = qsgi::Animation::still(scene);
        qsgi::sweepAnimationBounds(scene, still);
        if (!scene.animations.empty()) {
            double end = 0;
            for (const qsgi::KeyframeAnimation& a : scene.animations) end = std::max(end, a.endTime);
            const double fps = end > 4 ? 100 / end : 24;
            const qsgi::Animation animation = qsgi::Animation::fromGltf(scene, -1, fps, "fuzz.gltf");
            qsgi::checkLightsAreStatic(scene, animation, "fuzz.gltf");
            scene.setRestPose(animation.poseAt(0));
            scene.markDynamic(animation.movedNodes(), animation.morphedNodes());
            qsgi::sweepAnimationBounds(scene, animation);
            // As RenderJob: an animation that throws geometry beyond float range is refused.
            qsgi::checkSceneExtent(scene.positions, scene.animationBounds, "fuzz.gltf (--animation gltf)", "frames");
            for (int frame = 0; frame <= animation.lastFrame(); ++frame) {
                scene.applyPose(animation.poseAt(frame));
                for (size_t v = 0; v < scene.vertexCount(); ++v)
                    if (!qsgi::isFinite(scene.positions[v]) || !qsgi::isFinite(scene.normals[v])) std::abort();
            }
        }
        const float radius = qsgi::defaultRadius(scene);
        if (!std::isfinite(radius) || !(radius > 0)) std::abort();
        for (const qsgi::Vec3f& p : scene.positions)
            if (!qsgi::isFinite(p)) std::abort();
        for (const qsgi::Vec3f& n : scene.frontFaceNormals())
            if (!qsgi::isFinite(n)) std::abort();
    } catch (const qsgi::InputError&) {
    }
    return 0;
}
