#include "scene/back_sides.h"

#include <stdexcept>

namespace qsgi {

namespace {
// The back side's material: the front's, emitting nothing.
uint32_t backMaterial(Scene& scene, uint32_t front, std::vector<int64_t>& backOf) {
    if (backOf[front] >= 0) return uint32_t(backOf[front]);
    const Material& m = scene.materials[front];
    if (!m.isEmissive()) return uint32_t(backOf[front] = front);
    Material back = m;
    back.name += " (back)";
    back.emission = Vec3f(0.0f);
    back.emissive = TextureSlot{};
    scene.materials.push_back(std::move(back));
    return uint32_t(backOf[front] = int64_t(scene.materials.size() - 1));
}
}  // namespace

void addBackSides(Scene& scene) {
    if (scene.backSides) throw std::logic_error("addBackSides: the scene has its back sides already");
    const size_t fronts = scene.instances.size();
    Scene::BackSides sides;
    sides.firstVertex = uint32_t(scene.vertexCount());
    sides.firstTriangle = uint32_t(scene.triangleCount());
    sides.firstInstance = uint32_t(fronts);
    sides.backVertex.assign(scene.vertexCount(), Scene::BackSides::kNone);
    std::vector<int64_t> materialBack(scene.materials.size(), -1);
    bool any = false;
    for (size_t i = 0; i < fronts; ++i) {
        if (scene.instances[i].triangleCount == 0) continue;
        const uint32_t frontMaterial = scene.triangleMaterial[scene.instances[i].firstTriangle];
        if (!scene.materials[frontMaterial].doubleSided) continue;
        any = true;
        const uint32_t material = backMaterial(scene, frontMaterial, materialBack);
        MeshInstance back = scene.instances[i];
        const uint32_t firstFront = back.firstVertex;
        back.backOf = int(i);
        back.firstVertex = uint32_t(scene.vertexCount());
        back.firstTriangle = uint32_t(scene.triangleCount());
        for (Vec3f& n : back.objectNormals) n = -n;
        for (std::vector<Vec3f>& target : back.morphNormals)
            for (Vec3f& n : target) n = -n;
        for (uint32_t k = 0; k < back.vertexCount; ++k) {
            const uint32_t v = firstFront + k;
            sides.backVertex[v] = back.firstVertex + k;
            scene.positions.push_back(scene.positions[v]);
            scene.normals.push_back(-scene.normals[v]);
            scene.vertexHidden.push_back(scene.vertexHidden[v]);
            scene.vertexMaterial.push_back(material);
            for (std::vector<TexCoord>& set : scene.vertexTexCoords) set.push_back(set[v]);
            if (!scene.vertexColours.empty()) scene.vertexColours.push_back(scene.vertexColours[v]);
            if (!scene.vertexDynamic.empty()) scene.vertexDynamic.push_back(scene.vertexDynamic[v]);
        }
        const int64_t shift = int64_t(back.firstVertex) - int64_t(firstFront);
        for (uint32_t t = 0; t < back.triangleCount; ++t) {
            const uint32_t front = scene.instances[i].firstTriangle + t;
            const Triangle& f = scene.triangles[front];
            // Reversed winding: the back's geometric normal is the front's negated, to the bit.
            scene.triangles.push_back(Triangle{{uint32_t(f.v[0] + shift), uint32_t(f.v[2] + shift), uint32_t(f.v[1] + shift)}});
            scene.triangleMaterial.push_back(material);
            if (!scene.triangleDynamic.empty()) scene.triangleDynamic.push_back(scene.triangleDynamic[front]);
        }
        scene.placedWith.push_back(scene.placedWith[i]);
        scene.placedJoints.push_back(scene.placedJoints[i]);
        scene.placedWeights.push_back(scene.placedWeights[i]);
        scene.instances.push_back(std::move(back));
    }
    if (!any) return;
    scene.backSides = std::move(sides);
}

}  // namespace qsgi
