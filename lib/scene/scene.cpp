#include "scene/scene.h"

#include "util/error.h"

#include <algorithm>
#include <cstdio>
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

namespace {
// A quantity in a message, to three significant digits.
std::string threeDigits(double value) {
    char out[32];
    std::snprintf(out, sizeof out, "%.3g", value);
    return out;
}
}  // namespace

void checkSceneExtent(const std::vector<Vec3f>& positions, const Bounds3f& bounds, const std::string& file,
                      const std::string& place) {
    for (const Vec3f& p : positions)
        if (!isFinite(p))
            throw InputError(file, place, "places vertices beyond the range of float (a transform or position is too large)");
    const double extent = length(Vec3d(bounds.diagonal()));
    if (!(extent <= kMaxSceneExtent))
        throw InputError(file, place, "the scene spans " + threeDigits(extent) + " units; qsgi supports up to 1e15 "
                                      "(beyond that float areas overflow)");
    // An empty extent is a scene whose geometry all lies at one point (every node hidden by a
    // zero scale, at one origin), which is allowed.
    if (extent > 0 && extent < kMinSceneExtent)
        throw InputError(file, place, "the scene spans only " + threeDigits(extent) + " units; qsgi supports down to "
                                      "1e-9 (below that float areas underflow): scale the scene up");
}

void checkLightPowerAndPlace(const Scene& scene, const std::string& sceneFile, const std::string& configFile) {
    constexpr double kPi = 3.14159265358979323846;
    std::string file = sceneFile;
    auto refuse = [&](const std::string& place, double watts) {
        throw InputError(file, place, "carries " + threeDigits(watts) + " W, beyond the " + threeDigits(kMaxLightPower) +
                                          " W qsgi carries in float photon powers (scale the light's units down)");
    };
    const Bounds3f& bounds = scene.animationBounds;
    const double sceneRadius = 0.5 * length(Vec3d(bounds.diagonal()));
    double total = 0;
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const PunctualLight& l = scene.lights[i];
        const std::string place = l.name.empty() ? "lights[" + std::to_string(i) + "]" : l.name;
        file = l.node < 0 && !configFile.empty() ? configFile : sceneFile;
        const double strongest = std::max({double(l.intensity.x), double(l.intensity.y), double(l.intensity.z)});
        // Point and spot: 4 pi I at most; directional: the irradiance over the scene's cross-section.
        const double watts = l.type == LightType::Directional ? strongest * kPi * sceneRadius * sceneRadius : 4 * kPi * strongest;
        if (!(watts <= kMaxLightPower)) refuse(place, watts);
        total += watts;
        if (l.type != LightType::Directional) {
            const Vec3d p(l.position), lo(bounds.lower), hi(bounds.upper);
            const Vec3d outside(std::max({lo.x - p.x, 0.0, p.x - hi.x}), std::max({lo.y - p.y, 0.0, p.y - hi.y}),
                                std::max({lo.z - p.z, 0.0, p.z - hi.z}));
            const double distance = length(outside);
            if (!(distance <= kMaxSceneExtent))
                throw InputError(file, place, "lies " + threeDigits(distance) + " units from the scene; qsgi supports scenes "
                                              "(their lights included) spanning up to 1e15 units");
        }
    }
    file = sceneFile;
    auto refuseRadiance = [&](const std::string& place, double radiance) {
        throw InputError(file, place, "has a radiance of " + threeDigits(radiance) + " W m^-2 sr^-1, whose pi L (" +
                                          threeDigits(kPi * radiance) + " W/m^2) is beyond the " + threeDigits(kMaxIrradiance) +
                                          " W/m^2 qsgi carries in float irradiance (scale the light's units down)");
    };
    // The materials triangles use (a variant no triangle uses lights nothing).
    std::vector<uint8_t> used(scene.materials.size(), 0);
    for (const uint32_t m : scene.triangleMaterial) used[m] = 1;
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& m = scene.materials[i];
        if (used[i] && m.isEmissive() && !(kPi * double(maxComponent(m.emission)) <= kMaxIrradiance))
            refuseRadiance("materials: " + m.name, double(maxComponent(m.emission)));
    }
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const Material& m = scene.materials[scene.triangleMaterial[t]];
        if (!m.isEmissive()) continue;
        const double watts = kPi * double(maxComponent(m.emission)) * double(scene.triangleArea(t));
        if (!(watts <= kMaxLightPower)) refuse("materials: " + m.name, watts);
        total += watts;
    }
    if (scene.environment) {
        // π R² ∫ L dω, what enters the scene's bounding sphere (the photons carry exactly that).
        const Vec3d in = scene.environment->integral() * (kPi * sceneRadius * sceneRadius);
        const double watts = std::max({in.x, in.y, in.z});
        file = configFile.empty() ? "command line" : configFile;
        if (!(watts <= kMaxLightPower)) refuse("the sky or environment map", watts);
        float brightest = 0;
        for (const Vec3f& L : scene.environment->pixels()) brightest = std::max(brightest, maxComponent(L));
        if (!(kPi * double(brightest) <= kMaxIrradiance)) refuseRadiance("the sky or environment map", double(brightest));
        total += watts;
        file = sceneFile;
    }
    if (!(total <= kMaxLightPower)) refuse("its lights together", total);
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
    // The loader guarantees the hierarchy is a forest (no cycles). Each node's unresolved
    // ancestors are collected, then resolved from the top down: linear in the nodes, and no
    // recursion, so a chain of any depth cannot overflow the stack.
    std::vector<Transform> world(nodes.size());
    std::vector<uint8_t> done(nodes.size(), 0);
    std::vector<int> chain;
    for (size_t i = 0; i < nodes.size(); ++i) {
        for (int n = int(i); n >= 0 && !done[size_t(n)]; n = nodes[size_t(n)].parent) chain.push_back(n);
        for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
            const int parent = nodes[size_t(*it)].parent;
            world[size_t(*it)] = parent < 0 ? locals[size_t(*it)] : world[size_t(parent)] * locals[size_t(*it)];
            done[size_t(*it)] = 1;
        }
        chain.clear();
    }
    return world;
}

void Scene::placeInstance(size_t instanceIndex, const Transform& world, const std::vector<Transform>& jointMatrices,
                          const std::vector<double>& weights) {
    const MeshInstance& inst = instances[instanceIndex];
    // Object space, morphed by the weights.
    std::vector<Vec3d> objectPosition(inst.vertexCount), objectNormal(inst.objectNormals.empty() ? 0 : inst.vertexCount);
    for (uint32_t i = 0; i < inst.vertexCount; ++i) objectPosition[i] = Vec3d(inst.objectPositions[i]);
    for (uint32_t i = 0; i < objectNormal.size(); ++i) objectNormal[i] = Vec3d(inst.objectNormals[i]);
    for (size_t t = 0; t < inst.morphPositions.size() && t < weights.size(); ++t) {
        if (weights[t] == 0) continue;
        for (uint32_t i = 0; i < inst.vertexCount; ++i) objectPosition[i] += Vec3d(inst.morphPositions[t][i]) * weights[t];
        if (!objectNormal.empty() && !inst.morphNormals[t].empty())
            for (uint32_t i = 0; i < inst.vertexCount; ++i) objectNormal[i] += Vec3d(inst.morphNormals[t][i]) * weights[t];
    }
    // Each vertex's world transform: the skin's blend of joint matrices, or the node's.
    const bool skinned = inst.skin >= 0 && !jointMatrices.empty();
    auto vertexTransform = [&](uint32_t i) {
        if (!skinned) return world;
        Transform blend;
        blend.m.fill(0);
        double total = 0;
        for (int k = 0; k < inst.influences; ++k) {
            const size_t at = size_t(i) * size_t(inst.influences) + size_t(k);
            const double w = inst.skinWeights[at];
            if (w == 0) continue;
            const Transform& j = jointMatrices[inst.skinJoints[at]];
            for (int e = 0; e < 16; ++e) blend.m[size_t(e)] += w * j.m[size_t(e)];
            total += w;
        }
        // A vertex no joint holds stays with its node: only in scenes built in code, since the
        // loader gives a vertex whose weights are all zero weight 1 on its first joint.
        return total > 0 ? blend : world;
    };
    const bool transformNormals = !objectNormal.empty();
    const bool rigidHidden = !skinned && !world.isInvertible();
    const Vec3d hiddenAt = world.applyPoint(Vec3d(0.0));  // where a hidden rigid instance shrinks to
    const Transform rigidNormals = transformNormals && !skinned && !rigidHidden ? world.normalMatrix() : Transform();
    for (uint32_t i = 0; i < inst.vertexCount; ++i) {
        const uint32_t v = inst.firstVertex + i;
        const Transform m = skinned ? vertexTransform(i) : world;
        const bool hidden = skinned ? !m.isInvertible() : rigidHidden;
        vertexHidden[v] = hidden;
        // A hidden rigid instance shrinks to a point: a zero on one axis alone would leave
        // triangles with area that still block.
        positions[v] = Vec3f((rigidHidden ? hiddenAt : m.applyPoint(objectPosition[i])) - worldOrigin);
        if (hidden) {
            // The last finite normal stays; one never placed visible takes its object-space normal.
            if (!(dot(normals[v], normals[v]) > 0)) {
                const Vec3d n = objectNormal.empty() ? Vec3d(0.0) : normalize(objectNormal[i]);
                normals[v] = dot(n, n) > 0 && isFinite(Vec3f(n)) ? Vec3f(n) : Vec3f(0, 1, 0);  // any unit normal
            }
            continue;
        }
        if (transformNormals) {
            Vec3d n = normalize((skinned ? m.normalMatrix() : rigidNormals).applyVector(objectNormal[i]));
            if (!(dot(n, n) > 0) || !isFinite(Vec3f(n))) n = Vec3d(0, 1, 0);  // a degenerate blend: any unit normal
            normals[v] = Vec3f(n);
        }
    }
    if (!transformNormals) {
        // Area-weighted face normals: the unnormalised cross product is twice the area.
        std::vector<Vec3d> sum(inst.vertexCount, Vec3d(0.0));
        for (uint32_t t = 0; t < inst.triangleCount; ++t) {
            const Triangle& tri = triangles[inst.firstTriangle + t];
            const Vec3d a(positions[tri.v[0]]), b(positions[tri.v[1]]), c(positions[tri.v[2]]);
            const Vec3d n = cross(b - a, c - a);
            for (uint32_t k = 0; k < 3; ++k) sum[tri.v[k] - inst.firstVertex] += n;
        }
        for (uint32_t i = 0; i < inst.vertexCount; ++i) {
            if (vertexHidden[inst.firstVertex + i]) continue;
            Vec3d n = normalize(sum[i]);
            // A vertex of degenerate triangles only: any unit normal keeps estimators finite.
            if (dot(n, n) == 0) n = Vec3d(0, 1, 0);
            normals[inst.firstVertex + i] = Vec3f(n);
        }
    }
    placedWith[instanceIndex] = world;
    placedJoints[instanceIndex] = jointMatrices;
    placedWeights[instanceIndex] = weights;
}

namespace {
// A skinned instance's joint matrices J·IBM for the given world transforms.
std::vector<Transform> jointMatricesOf(const Scene& scene, const MeshInstance& inst, const std::vector<Transform>& world) {
    std::vector<Transform> out;
    if (inst.skin < 0) return out;
    const Skin& skin = scene.skins[size_t(inst.skin)];
    out.reserve(skin.joints.size());
    for (size_t j = 0; j < skin.joints.size(); ++j) out.push_back(world[size_t(skin.joints[j])] * skin.inverseBind[j]);
    return out;
}

const std::vector<double>& weightsOf(const MeshInstance& inst, const Pose& pose) {
    const size_t node = size_t(inst.node);
    if (inst.morphPositions.empty() || node >= pose.morphWeights.size() || pose.morphWeights[node].empty())
        return inst.morphRest;
    return pose.morphWeights[node];
}
}  // namespace

Bounds3f Scene::instanceBounds(size_t instanceIndex) const {
    const MeshInstance& inst = instances[instanceIndex];
    Bounds3f b;
    for (uint32_t i = 0; i < inst.vertexCount; ++i) b.extend(positions[inst.firstVertex + i]);
    return b;
}

bool Scene::applyPose(const Pose& pose, std::vector<uint32_t>* moved, std::vector<Bounds3f>* movedBounds) {
    const std::vector<Transform> world = worldTransforms(pose.locals);
    bool any = false;
    for (size_t i = 0; i < instances.size(); ++i) {
        const MeshInstance& inst = instances[i];
        const Transform& w = world[size_t(inst.node)];
        const std::vector<Transform> joints = jointMatricesOf(*this, inst, world);
        const std::vector<double>& weights = weightsOf(inst, pose);
        // A skinned mesh follows its joints only; a rigid one its node.
        const bool same = (inst.skin >= 0 ? joints == placedJoints[i] : w == placedWith[i]) && weights == placedWeights[i];
        if (same) continue;
        if (movedBounds) movedBounds->push_back(instanceBounds(i));
        placeInstance(i, w, joints, weights);
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

void Scene::setRestPose(const Pose& pose) {
    for (size_t i = 0; i < nodes.size(); ++i) nodes[i].local = pose.locals[i];
    applyPose(pose);
    for (MeshInstance& inst : instances) inst.morphRest = weightsOf(inst, pose);
    const std::vector<Transform> world = worldTransforms(pose.locals);
    for (PunctualLight& l : lights)
        if (l.node >= 0) placeLight(l, world[size_t(l.node)], worldOrigin);
    if (camera && camera->node >= 0) camera = placeCamera(*camera, world[size_t(camera->node)], worldOrigin);
    for (auto& c : cameras)
        if (c && c->node >= 0) c = placeCamera(*c, world[size_t(c->node)], worldOrigin);
}

std::vector<uint8_t> Scene::dynamicInstances(const std::vector<int>& movedNodes, const std::vector<int>& morphedNodes) const {
    std::vector<uint8_t> nodeDynamic(nodes.size(), 0);
    // A moved node's whole subtree moves; marked with an explicit stack, so a chain of any depth
    // cannot overflow the call stack (as worldTransforms).
    std::vector<int> pending(movedNodes.begin(), movedNodes.end());
    while (!pending.empty()) {
        const int n = pending.back();
        pending.pop_back();
        if (nodeDynamic[size_t(n)]) continue;
        nodeDynamic[size_t(n)] = 1;
        for (int c : nodes[size_t(n)].children) pending.push_back(c);
    }
    std::vector<uint8_t> morphed(nodes.size(), 0);
    for (int n : morphedNodes) morphed[size_t(n)] = 1;
    std::vector<uint8_t> out(instances.size(), 0);
    for (size_t i = 0; i < instances.size(); ++i) {
        const MeshInstance& inst = instances[i];
        bool dynamic = nodeDynamic[size_t(inst.node)] || (!inst.morphPositions.empty() && morphed[size_t(inst.node)]);
        if (inst.skin >= 0)
            for (int j : skins[size_t(inst.skin)].joints) dynamic = dynamic || nodeDynamic[size_t(j)];
        out[i] = dynamic;
    }
    return out;
}

void Scene::markDynamic(const std::vector<int>& movedNodes, const std::vector<int>& morphedNodes) {
    const std::vector<uint8_t> dynamic = dynamicInstances(movedNodes, morphedNodes);
    vertexDynamic.assign(positions.size(), 0);
    triangleDynamic.assign(triangles.size(), 0);
    for (size_t i = 0; i < instances.size(); ++i) {
        const MeshInstance& inst = instances[i];
        if (!dynamic[i]) continue;
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
                        const std::vector<uint32_t>& indices, uint32_t material, const Transform* restWorld) {
    Transform world;  // rest pose, composed up the (acyclic) hierarchy unless the caller has it
    if (restWorld) {
        world = *restWorld;
    } else {
        world = nodes[node].local;
        for (int p = nodes[node].parent; p >= 0; p = nodes[p].parent) world = nodes[p].local * world;
    }
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
    normals.resize(normals.size() + inst.vertexCount, Vec3f(0.0f));
    vertexHidden.resize(vertexHidden.size() + inst.vertexCount, 0);
    if (!coverEdges.empty()) coverEdges.resize(positions.size(), 0.0f);
    vertexMaterial.resize(vertexMaterial.size() + inst.vertexCount, material);
    for (std::vector<TexCoord>& set : vertexTexCoords) set.resize(positions.size());
    if (!vertexColours.empty()) vertexColours.resize(positions.size(), Rgba{1, 1, 1, 1});
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
    placedJoints.assign(instances.size(), {});
    placedWeights.assign(instances.size(), {});
    for (size_t i = 0; i < instances.size(); ++i)
        placeInstance(i, world[size_t(instances[i].node)], jointMatricesOf(*this, instances[i], world), instances[i].morphRest);
    markDynamic({});
    animationBounds = bounds();
}

bool Scene::hasDynamicGeometry() const {
    for (uint8_t d : triangleDynamic)
        if (d) return true;
    return false;
}

}  // namespace qsgi
