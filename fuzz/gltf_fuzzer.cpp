// Fuzzes the glTF loader through qsgi's scene building: tinygltf's parser behind our document
// checks, accessor decoding, the node hierarchy, materials, lights and cameras, then what
// RenderJob computes from a scene before tracing (animation bounds, default radius, face
// normals). Only InputError may leave qsgi's code, and no position or normal may be non-finite.
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
