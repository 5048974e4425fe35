// A light tree (Conty Estevez & Kulla 2018, "Importance sampling of many lights with adaptive tree
// splitting"; pbrt-v4's BVHLightSampler, Cycles' light tree): a binary tree over the emitters that
// exact direct light samples (DirectLight), each node bounding its emitters' positions, power and
// the directions they send light in. A shading point p with normal n descends from the root,
// choosing each child in proportion to a conservative bound of what the child's emitters can send
// to p (importance()), until it reaches a leaf or a panel — a node of emitters that all face one
// way and tile its box (kPanelFill) — and chooses among its emitters by their intensity, as
// direct light chose among all emitters by power before the tree. The bounds steer where emitters
// differ in what they send p (far along a corridor, turned away); over one panel (data/cornell's
// 32 triangles) intensity is the better guide, and the panel's emitters stay stratified by the
// Sobol point as a whole (descending into it raised data/cornell's interior error from 0.0075 to
// 0.0083). The probability of the
// chosen emitter is the product of the choices along its path and its share of the node, so
// dividing its contribution by it keeps the estimate unbiased; a child that certainly sends
// nothing to p has importance 0 and is never chosen, and every emitter
// that can light p has a probability above 0.
//
// The tree is built once (lights are static, docs/design.md §2), single-threaded, in a fixed
// order: the same tree for any thread count, and a pure function of the emitters given.
#pragma once

#include <cstdint>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

// What bounds the light of one emitter or a group of them: where they are (box), how strongly
// they send it (phi: the luminance of their intensity, W/sr — a light's I, a triangle's L_e A
// along its normal — so that phi cosθ / d² bounds the irradiance each type brings alike; summed
// over a group), and the directions of their surfaces' normals (the
// cone about unit `axis` of half-angle θo, cosTheta_o) widened by how far from a normal they still
// emit (θe, cosTheta_e: π/2 for a Lambertian surface, 0 for a spot light beyond its cone).
struct LightBounds {
    Bounds3f box;
    double phi = 0;
    Vec3d axis{0, 0, 1};
    double cosTheta_o = 1;  // −1: every direction (a point light)
    double cosTheta_e = 0;
    double area = 0;  // the triangles' (0 for lights)

    // A one-sided Lambertian triangle with the given corners, unit front normal and L_e A.
    static LightBounds triangle(const Vec3f corner[3], const Vec3d& normal, double phi);
    // A point light (every direction) or a spot light that sends light within angle acos(cosOuter)
    // of `direction` (unit), of intensity phi.
    static LightBounds point(const Vec3f& position, double phi);
    static LightBounds spot(const Vec3f& position, const Vec3d& direction, double cosOuter, double phi);

    // Bounds of both (phi summed, the smallest cone found about both cones, the wider θe).
    static LightBounds unite(const LightBounds& a, const LightBounds& b);

    // A bound, up to a common factor, of the irradiance the emitters can send to a point p whose
    // surface faces unit n (the light must arrive from n's side): phi · cosθ' / d² · cosθ'_i with
    // the angles widened by the box's subtended cone and d² no less than the box's radius squared.
    // 0 only where no emitter inside can send p anything.
    double importance(const Vec3d& p, const Vec3d& n) const;
};

class LightTree {
public:
    // A node of emitters that all face one way and cover at least kPanelFill of its box's
    // largest face is a panel: chosen among by intensity, never descended.
    static constexpr double kPanelFill = 0.5;

    LightTree() = default;
    // Emitter i is bounds[i]; emitters with phi = 0 are left out.
    explicit LightTree(const std::vector<LightBounds>& bounds);

    bool empty() const { return nodes_.empty(); }
    size_t nodeCount() const { return nodes_.size(); }
    size_t bytes() const {
        return nodes_.capacity() * sizeof(Node) + (leafOf_.capacity() + positionOf_.capacity() + order_.capacity()) * sizeof(uint32_t) +
               running_.capacity() * sizeof(double);
    }

    struct Choice {
        uint32_t emitter = 0;
        double probability = 0;  // of choosing it at this point
    };
    // Descends from the root with u in [0, 1) and chooses in the node p sees whole with what is
    // left of u: false if nothing can light (p, n). A tree of one emitter returns it with
    // probability 1 without asking its importance, which is exactly what sampling among one
    // emitter by power did.
    bool sample(const Vec3d& p, const Vec3d& n, double u, Choice& choice) const;
    // The probability that sample() chooses `emitter` at (p, n): the product along its path.
    double probability(const Vec3d& p, const Vec3d& n, uint32_t emitter) const;

    // For tests: node i's bounds, its children (−1 for a leaf) and a leaf's emitters.
    struct Node {
        LightBounds bounds;
        int32_t second = -1;   // an interior node's second child; its first is the next node
        int32_t parent = -1;
        uint32_t first = 0, count = 0;  // its emitters: order_[first, first + count)
        bool panel = false;             // chosen among by intensity, not descended
        bool leaf() const { return second < 0; }
    };
    const Node& node(size_t i) const { return nodes_[i]; }
    uint32_t leafEmitter(const Node& leaf, uint32_t k) const { return order_[leaf.first + k]; }

private:
    // An emitter as the build sorts it: its bounds beside its index, so that the build's passes
    // over a node's emitters read memory in order (through an index they missed the cache on every
    // emitter: a million lights took 11 s to build).
    struct Item {
        LightBounds bounds;
        Vec3f centre;
        uint32_t emitter;
    };
    // Builds the subtree over items[first, last) at nodes_.size(); returns its index.
    int32_t build(std::vector<Item>& items, size_t first, size_t last, int32_t parent, int depth);

    // Whether sample() stops at `node` (a leaf or a panel), and the emitter's share of its intensity.
    bool seenWhole(const Node& node) const { return node.leaf() || node.panel; }
    double shareInNode(const Node& node, uint32_t emitter) const;

    std::vector<Node> nodes_;
    std::vector<uint32_t> leafOf_;      // per emitter, its leaf (UINT32_MAX if left out)
    std::vector<uint32_t> order_;       // the emitters in the leaves' order: every node's are consecutive
    std::vector<uint32_t> positionOf_;  // per emitter, its place in order_
    std::vector<double> running_;       // the running sum of order_'s intensities, from 0
};

}  // namespace qsgi
