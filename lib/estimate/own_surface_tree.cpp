#include "estimate/own_surface_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "estimate/morton_order.h"

namespace qsgi {

namespace {
constexpr uint32_t kLeafTriangles = 8;

double maxAbs(const Vec3d& v) { return std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}); }

// Largest direction · x over the box's points.
double boxMaxDot(const Bounds3f& box, const Vec3d& d) {
    double sum = 0;
    for (int a = 0; a < 3; ++a) sum += std::max(d[a] * double(box.lower[a]), d[a] * double(box.upper[a]));
    return sum;
}
}  // namespace

OwnSurfaceTree::OwnSurfaceTree(const Scene& scene, const std::vector<Vec3f>& frontNormals, const MeshTopology& topology) {
    vertexPiece_ = topology.vertexPieces(scene.triangles);
    trianglePiece_.resize(scene.triangleCount());
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) trianglePiece_[t] = vertexPiece_[scene.triangles[t].v[0]];
    if (scene.triangleCount() == 0) return;
    std::vector<Vec3f> centroids(scene.triangleCount());
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const Triangle& T = scene.triangles[t];
        centroids[t] = (scene.positions[T.v[0]] + scene.positions[T.v[1]] + scene.positions[T.v[2]]) * (1.0f / 3.0f);
    }
    order_ = mortonOrder(centroids);
    // Median splits leave 4 to 8 triangles a leaf: at most n/2 nodes.
    nodes_.reserve(order_.size() / 2 + 1);
    build(0, uint32_t(order_.size()), scene, frontNormals);
}

uint32_t OwnSurfaceTree::build(uint32_t begin, uint32_t end, const Scene& scene, const std::vector<Vec3f>& frontNormals) {
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.emplace_back();
    Node node;
    node.begin = begin;
    node.end = end;
    if (end - begin <= kLeafTriangles) {
        Vec3d normalSum(0.0);
        for (uint32_t i = begin; i < end; ++i) {
            const uint32_t t = order_[i];
            for (uint32_t v : scene.triangles[t].v) node.box.extend(scene.positions[v]);
            node.normals.extend(frontNormals[t]);
            normalSum += Vec3d(frontNormals[t]);
        }
        node.axis = length(normalSum) > 0 ? normalize(normalSum) : Vec3d(0, 0, 1);
        node.centre = (Vec3d(node.box.lower) + Vec3d(node.box.upper)) * 0.5;
        node.piece = trianglePiece_[order_[begin]];
        for (uint32_t i = begin; i < end; ++i)
            if (trianglePiece_[order_[i]] != node.piece) node.piece = kMixed;
        node.slabLo = std::numeric_limits<double>::max();
        node.slabHi = -std::numeric_limits<double>::max();
        for (uint32_t i = begin; i < end; ++i)
            for (uint32_t v : scene.triangles[order_[i]].v) {
                const Vec3d p(scene.positions[v]);
                node.slabLo = std::min(node.slabLo, dot(node.axis, p));
                node.slabHi = std::max(node.slabHi, dot(node.axis, p));
                node.radius = std::max(node.radius, length(p - node.centre));
            }
    } else {
        const uint32_t middle = begin + (end - begin) / 2;
        node.left = build(begin, middle, scene, frontNormals);
        node.right = build(middle, end, scene, frontNormals);
        const Node& a = nodes_[node.left];
        const Node& b = nodes_[node.right];
        node.piece = a.piece == b.piece ? a.piece : kMixed;
        node.box = a.box;
        node.box.extend(b.box);
        node.normals = a.normals;
        node.normals.extend(b.normals);
        const Vec3d axisSum = a.axis * double(a.end - a.begin) + b.axis * double(b.end - b.begin);
        node.axis = length(axisSum) > 0 ? normalize(axisSum) : Vec3d(0, 0, 1);
        node.centre = (Vec3d(node.box.lower) + Vec3d(node.box.upper)) * 0.5;
        // The children's own bounds along the new axis: conservative, and tight where they agree.
        node.slabHi = std::max(maxDot(a, node.axis), maxDot(b, node.axis));
        node.slabLo = std::min(-maxDot(a, -node.axis), -maxDot(b, -node.axis));
        node.radius = std::max(length(a.centre - node.centre) + a.radius, length(b.centre - node.centre) + b.radius);
    }
    nodes_[index] = node;
    return index;
}

double OwnSurfaceTree::slabMaxDot(const Node& node, const Vec3d& d) {
    const double along = dot(d, node.axis);
    const Vec3d across = d - node.axis * along;
    return std::max(along * node.slabLo, along * node.slabHi) + dot(across, node.centre) + length(across) * node.radius;
}

double OwnSurfaceTree::maxDot(const Node& node, const Vec3d& d) { return std::min(boxMaxDot(node.box, d), slabMaxDot(node, d)); }

bool OwnSurfaceTree::mayRise(const Node& node, const Vec3d& centre, const Vec3d& normal, double minNormalDot, double reach,
                             double height) const {
    // Rounding: the bounds are sums of a few products of coordinates; 2^-40 of their size is far
    // more than double precision loses, and far less than any height the callers compare.
    const double margin = 0x1p-40 * (maxAbs(centre) + maxAbs(node.centre) + node.radius + reach);
    double gap2 = 0;
    for (int a = 0; a < 3; ++a) {
        const double gap = std::max({double(node.box.lower[a]) - centre[a], centre[a] - double(node.box.upper[a]), 0.0});
        gap2 += gap * gap;
    }
    if (gap2 > (reach + margin) * (reach + margin)) return false;
    // Front normals are floats, their dot with n_v is taken in float: a margin of 1e-6.
    if (boxMaxDot(node.normals, normal) + 1e-6 <= minNormalDot) return false;
    // The box first: exact on axis-aligned geometry, and cheaper than the slab.
    const double base = dot(normal, centre) - margin;
    if (boxMaxDot(node.box, normal) - base < height) return false;
    return slabMaxDot(node, normal) - base >= height;
}

}  // namespace qsgi
