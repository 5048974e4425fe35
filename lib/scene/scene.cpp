#include "scene/scene.h"

#include <functional>

namespace qsgi {

Bounds3f Scene::bounds() const {
    Bounds3f b;
    for (const auto& p : positions) b.extend(p);
    return b;
}

Vec3f Scene::geometricNormal(uint32_t tri) const {
    const Triangle& t = triangles[tri];
    const Vec3d a(positions[t.v[0]]), b(positions[t.v[1]]), c(positions[t.v[2]]);
    return Vec3f(normalize(cross(b - a, c - a)));
}

float Scene::triangleArea(uint32_t tri) const {
    const Triangle& t = triangles[tri];
    const Vec3d a(positions[t.v[0]]), b(positions[t.v[1]]), c(positions[t.v[2]]);
    return float(0.5 * length(cross(b - a, c - a)));
}

std::vector<Transform> Scene::restLocals() const {
    std::vector<Transform> locals(nodes.size());
    for (size_t i = 0; i < nodes.size(); ++i) locals[i] = nodes[i].local;
    return locals;
}

std::vector<Transform> Scene::worldTransforms(const std::vector<Transform>& locals) const {
    // The loader guarantees the hierarchy is a forest (no cycles), so recursion terminates.
    std::vector<Transform> world(nodes.size());
    std::vector<uint8_t> done(nodes.size(), 0);
    std::function<const Transform&(int)> resolve = [&](int i) -> const Transform& {
        if (!done[i]) {
            world[i] = nodes[i].parent < 0 ? locals[i] : resolve(nodes[i].parent) * locals[i];
            done[i] = 1;
        }
        return world[i];
    };
    for (size_t i = 0; i < nodes.size(); ++i) resolve(int(i));
    return world;
}

void Scene::placeInstance(size_t instanceIndex, const Transform& world) {
    const MeshInstance& inst = instances[instanceIndex];
    for (uint32_t i = 0; i < inst.vertexCount; ++i)
        positions[inst.firstVertex + i] = Vec3f(world.applyPoint(Vec3d(inst.objectPositions[i])) - worldOrigin);
    if (!inst.objectNormals.empty()) {
        const Transform nm = world.normalMatrix();
        for (uint32_t i = 0; i < inst.vertexCount; ++i)
            normals[inst.firstVertex + i] = Vec3f(normalize(nm.applyVector(Vec3d(inst.objectNormals[i]))));
    } else {
        // Area-weighted face normals: the unnormalised cross product is twice the area.
        for (uint32_t i = 0; i < inst.vertexCount; ++i) normals[inst.firstVertex + i] = Vec3f(0.0f);
        std::vector<Vec3d> sum(inst.vertexCount, Vec3d(0.0));
        for (uint32_t t = 0; t < inst.triangleCount; ++t) {
            const Triangle& tri = triangles[inst.firstTriangle + t];
            const Vec3d a(positions[tri.v[0]]), b(positions[tri.v[1]]), c(positions[tri.v[2]]);
            const Vec3d n = cross(b - a, c - a);
            for (uint32_t k = 0; k < 3; ++k) sum[tri.v[k] - inst.firstVertex] += n;
        }
        for (uint32_t i = 0; i < inst.vertexCount; ++i) {
            Vec3d n = normalize(sum[i]);
            // A vertex of degenerate triangles only: any unit normal keeps estimators finite.
            if (dot(n, n) == 0) n = Vec3d(0, 1, 0);
            normals[inst.firstVertex + i] = Vec3f(n);
        }
    }
    placedWith[instanceIndex] = world;
}

bool Scene::applyPose(const std::vector<Transform>& locals) {
    const std::vector<Transform> world = worldTransforms(locals);
    bool moved = false;
    for (size_t i = 0; i < instances.size(); ++i) {
        const Transform& w = world[instances[i].node];
        if (w == placedWith[i]) continue;
        placeInstance(i, w);
        moved = true;
    }
    return moved;
}

void Scene::markDynamic(const std::vector<int>& movedNodes) {
    std::vector<uint8_t> nodeDynamic(nodes.size(), 0);
    std::function<void(int)> mark = [&](int n) {
        if (nodeDynamic[n]) return;
        nodeDynamic[n] = 1;
        for (int c : nodes[n].children) mark(c);
    };
    for (int n : movedNodes) mark(n);
    vertexDynamic.assign(positions.size(), 0);
    triangleDynamic.assign(triangles.size(), 0);
    for (const MeshInstance& inst : instances) {
        if (!nodeDynamic[inst.node]) continue;
        std::fill_n(vertexDynamic.begin() + inst.firstVertex, inst.vertexCount, 1);
        std::fill_n(triangleDynamic.begin() + inst.firstTriangle, inst.triangleCount, 1);
    }
}

bool Scene::hasDynamicGeometry() const {
    for (uint8_t d : triangleDynamic)
        if (d) return true;
    return false;
}

}  // namespace qsgi
