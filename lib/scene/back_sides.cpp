#include "scene/back_sides.h"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <tuple>

namespace qsgi {

namespace {
// An instance whose triangles close a volume, each edge (vertices welded by exact position) met by
// exactly two triangles that run along it in opposite directions, and whose material lets no
// light through (no cut-out, blend or transmission): no light reaches its inside, whose every
// cover ray meets a back face there. Its back sides would be 0 by the cover rule; they are not
// made at all, so they cost nothing.
bool sealedInside(const Scene& scene, const MeshInstance& inst, const Material& material) {
    if (material.letsLightThrough() || material.transmission > 0 || inst.triangleCount == 0) return false;
    std::map<std::tuple<float, float, float>, uint32_t> weld;
    auto id = [&](uint32_t v) {
        const Vec3f& p = scene.positions[v];
        return weld.emplace(std::make_tuple(p.x + 0.0f, p.y + 0.0f, p.z + 0.0f), uint32_t(weld.size())).first->second;
    };
    std::map<std::pair<uint32_t, uint32_t>, int> edges;  // directed edge -> how often
    for (uint32_t t = inst.firstTriangle; t < inst.firstTriangle + inst.triangleCount; ++t) {
        const Triangle& tri = scene.triangles[t];
        const uint32_t c[3] = {id(tri.v[0]), id(tri.v[1]), id(tri.v[2])};
        if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) return false;  // degenerate: not a clean surface
        for (int k = 0; k < 3; ++k) ++edges[{c[k], c[(k + 1) % 3]}];
    }
    for (const auto& [edge, count] : edges) {
        const auto reverse = edges.find({edge.second, edge.first});
        if (count != 1 || reverse == edges.end() || reverse->second != 1) return false;
    }
    return true;
}

// The back side's material: the front's, emitting nothing.
uint32_t backMaterial(Scene& scene, uint32_t front, std::vector<int64_t>& copyOf) {
    if (copyOf[front] >= 0) return uint32_t(copyOf[front]);
    const Material& m = scene.materials[front];
    if (!m.isEmissive()) return uint32_t(copyOf[front] = front);
    Material back = m;
    back.name += " (back)";
    back.emission = Vec3f(0.0f);
    back.emissive = TextureSlot{};
    scene.materials.push_back(std::move(back));
    return uint32_t(copyOf[front] = int64_t(scene.materials.size() - 1));
}
}  // namespace

std::vector<uint8_t> instancesWithBackSides(const Scene& scene) {
    std::vector<uint8_t> which(scene.instances.size(), 0);
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const MeshInstance& inst = scene.instances[i];
        if (inst.backOf >= 0 || inst.triangleCount == 0) continue;
        const Material& material = scene.materials[scene.triangleMaterial[inst.firstTriangle]];
        which[i] = material.doubleSided && !sealedInside(scene, inst, material);
    }
    return which;
}

void addBackSides(Scene& scene) { addBackSides(scene, instancesWithBackSides(scene)); }

void addBackSides(Scene& scene, const std::vector<uint8_t>& which) {
    if (scene.backSides) throw std::logic_error("addBackSides: the scene has its back sides already");
    if (which.size() != scene.instances.size()) throw std::logic_error("addBackSides: one choice per instance");
    const size_t fronts = scene.instances.size();
    Scene::BackSides sides;
    sides.firstVertex = uint32_t(scene.vertexCount());
    sides.firstTriangle = uint32_t(scene.triangleCount());
    sides.firstInstance = uint32_t(fronts);
    sides.firstMaterial = uint32_t(scene.materials.size());
    sides.backVertex.assign(scene.vertexCount(), Scene::BackSides::kNone);
    std::vector<int64_t> materialBack(scene.materials.size(), -1);
    bool any = false;
    for (size_t i = 0; i < fronts; ++i) {
        if (scene.instances[i].triangleCount == 0) continue;
        const uint32_t frontMaterial = scene.triangleMaterial[scene.instances[i].firstTriangle];
        if (!scene.materials[frontMaterial].doubleSided) continue;
        any = true;  // the outputs carry back values, 0 where no back side is made
        if (!which[i]) continue;
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
            if (!scene.coverEdges.empty()) scene.coverEdges.push_back(scene.coverEdges[v]);
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
