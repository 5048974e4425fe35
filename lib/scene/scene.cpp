#include "scene/scene.h"

#include "util/error.h"

#include <cstdio>
#include <functional>
#include <limits>

namespace qsgi {

Bounds3f Scene::bounds() const {
    Bounds3f b;
    for (const auto& p : positions) b.extend(p);
    return b;
}

Vec3f frontFaceNormal(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals, const Triangle& t) {
    const Vec3d a(positions[t.v[0]]), b(positions[t.v[1]]), c(positions[t.v[2]]);
    const Vec3f g(normalize(cross(b - a, c - a)));
    return dot(g, normals[t.v[0]] + normals[t.v[1]] + normals[t.v[2]]) < 0 ? -g : g;
}

std::vector<Vec3f> Scene::frontFaceNormals() const {
    std::vector<Vec3f> front(triangleCount());
    for (uint32_t t = 0; t < triangleCount(); ++t) front[t] = frontFaceNormal(positions, normals, triangles[t]);
    return front;
}

void checkSceneExtent(const std::vector<Vec3f>& positions, const Bounds3f& bounds, const std::string& file,
                      const std::string& place) {
    for (const Vec3f& p : positions)
        if (!isFinite(p))
            throw InputError(file, place, "places vertices beyond the range of float (a transform or position is too large)");
    const double extent = length(Vec3d(bounds.diagonal()));
    if (!(extent <= kMaxSceneExtent)) {
        char spans[32];
        std::snprintf(spans, sizeof spans, "%.3g", extent);
        throw InputError(file, place, std::string("the scene spans ") + spans + " units; qsgi supports up to 1e15 "
                                      "(beyond that float areas overflow)");
    }
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

Bounds3f Scene::instanceBounds(size_t instanceIndex) const {
    const MeshInstance& inst = instances[instanceIndex];
    Bounds3f b;
    for (uint32_t i = 0; i < inst.vertexCount; ++i) b.extend(positions[inst.firstVertex + i]);
    return b;
}

bool Scene::applyPose(const std::vector<Transform>& locals, std::vector<uint32_t>* moved, std::vector<Bounds3f>* movedBounds) {
    const std::vector<Transform> world = worldTransforms(locals);
    bool any = false;
    for (size_t i = 0; i < instances.size(); ++i) {
        const Transform& w = world[instances[i].node];
        if (w == placedWith[i]) continue;
        if (movedBounds) movedBounds->push_back(instanceBounds(i));
        placeInstance(i, w);
        if (movedBounds) movedBounds->push_back(instanceBounds(i));
        if (moved) moved->push_back(uint32_t(i));
        any = true;
    }
    return any;
}

void placeLight(PunctualLight& light, const Transform& world, const Vec3d& worldOrigin) {
    light.position = Vec3f(world.applyPoint(Vec3d(0.0)) - worldOrigin);
    light.direction = Vec3f(normalize(world.applyVector(Vec3d(0, 0, -1))));
}

void Scene::setRestPose(const std::vector<Transform>& locals) {
    for (size_t i = 0; i < nodes.size(); ++i) nodes[i].local = locals[i];
    applyPose(locals);
    const std::vector<Transform> world = worldTransforms(locals);
    for (PunctualLight& l : lights)
        if (l.node >= 0) placeLight(l, world[size_t(l.node)], worldOrigin);
    if (camera && camera->node >= 0) camera = placeCamera(*camera, world[size_t(camera->node)], worldOrigin);
    for (auto& c : cameras)
        if (c && c->node >= 0) c = placeCamera(*c, world[size_t(c->node)], worldOrigin);
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

int Scene::addNode(std::string name, const Transform& local, int parent) {
    SceneNode n;
    n.name = std::move(name);
    n.local = local;
    n.parent = parent;
    nodes.push_back(std::move(n));
    const int index = int(nodes.size() - 1);
    if (parent >= 0) nodes[parent].children.push_back(index);
    return index;
}

void Scene::addInstance(int node, std::vector<Vec3f> objectPositions, std::vector<Vec3f> objectNormals,
                        const std::vector<uint32_t>& indices, uint32_t material) {
    Transform world = nodes[node].local;  // rest pose, composed up the (acyclic) hierarchy
    for (int p = nodes[node].parent; p >= 0; p = nodes[p].parent) world = nodes[p].local * world;
    MeshInstance inst;
    inst.node = node;
    inst.firstVertex = uint32_t(positions.size());
    inst.vertexCount = uint32_t(objectPositions.size());
    inst.firstTriangle = uint32_t(triangles.size());
    inst.triangleCount = uint32_t(indices.size() / 3);
    inst.mirrored = world.determinant3x3() < 0;
    inst.objectPositions = std::move(objectPositions);
    inst.objectNormals = std::move(objectNormals);
    positions.resize(positions.size() + inst.vertexCount);
    normals.resize(normals.size() + inst.vertexCount);
    vertexMaterial.resize(vertexMaterial.size() + inst.vertexCount, material);
    for (size_t t = 0; t + 2 < indices.size(); t += 3) {
        // A mirroring transform reverses the winding; swapping keeps the front side CCW in world space.
        Triangle out{{inst.firstVertex + indices[t], inst.firstVertex + indices[t + 1], inst.firstVertex + indices[t + 2]}};
        if (inst.mirrored) std::swap(out.v[1], out.v[2]);
        triangles.push_back(out);
        triangleMaterial.push_back(material);
    }
    instances.push_back(std::move(inst));
}

void Scene::finalize() {
    const std::vector<Transform> world = worldTransforms(restLocals());
    // Centre of the rest-pose world bounds, in double precision.
    Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const MeshInstance& inst : instances)
        for (const Vec3f& p : inst.objectPositions) {
            const Vec3d w = world[inst.node].applyPoint(Vec3d(p));
            lo = min(lo, w);
            hi = max(hi, w);
        }
    worldOrigin = lo.x <= hi.x ? (lo + hi) * 0.5 : Vec3d(0.0);
    for (PunctualLight& l : lights) l.position = Vec3f(Vec3d(l.position) - worldOrigin);
    if (camera) camera->position = Vec3f(Vec3d(camera->position) - worldOrigin);
    for (auto& c : cameras)
        if (c) c->position = Vec3f(Vec3d(c->position) - worldOrigin);
    placedWith.assign(instances.size(), Transform());
    for (size_t i = 0; i < instances.size(); ++i) placeInstance(i, world[instances[i].node]);
    markDynamic({});
    animationBounds = bounds();
}

bool Scene::hasDynamicGeometry() const {
    for (uint8_t d : triangleDynamic)
        if (d) return true;
    return false;
}

}  // namespace qsgi
