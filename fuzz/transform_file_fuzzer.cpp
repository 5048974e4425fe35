// Fuzzes the transform-file reader (docs/design.md §3): JSON parsing as readJsonFile does it, then
// Animation::parseTransformFile against a small scene with a mesh, a child mesh and a light, and
// the checks RenderJob runs on the result. Only InputError may leave qsgi's code.
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>

#include "scene/animation.h"
#include "util/error.h"

namespace {

qsgi::Scene makeScene() {
    using namespace qsgi;
    Scene scene;
    scene.sourcePath = "fuzz-scene";
    scene.materials.push_back(Material{"grey", Vec3f(0.5f), Vec3f(0.0f)});
    const int floor = scene.addNode("Floor", Transform());
    const int box = scene.addNode("Box", Transform(), floor);
    scene.addNode("Lamp", Transform());
    const std::vector<Vec3f> quad = {{-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}};
    scene.addInstance(floor, quad, {}, {0, 1, 2, 0, 2, 3}, 0);
    scene.addInstance(box, {{0, 0.5f, 0}, {0.2f, 0.5f, 0}, {0, 0.5f, 0.2f}}, {}, {0, 1, 2}, 0);
    PunctualLight light;
    light.node = 2;
    light.position = Vec3f(0, 1, 0);
    scene.lights.push_back(light);
    scene.finalize();
    return scene;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static qsgi::Scene scene = makeScene();
    const nlohmann::json doc = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
    if (doc.is_discarded()) return 0;  // readJsonFile's "not valid JSON"
    try {
        const qsgi::Animation animation = qsgi::Animation::parseTransformFile("fuzz.json", doc, scene);
        qsgi::checkLightsAreStatic(scene, animation, "fuzz.json");
        for (int frame : {0, animation.lastFrame() / 2, animation.lastFrame(), animation.lastFrame() + 1})
            scene.applyPose(animation.localsAt(frame));
        scene.applyPose(scene.restLocals());
    } catch (const qsgi::InputError&) {
    } catch (const nlohmann::json::exception&) {
        // fromTransformFile turns these into InputError
    }
    return 0;
}
