#include "trace/light_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace qsgi {

namespace {

constexpr double kPiD = 3.14159265358979323846;

// A spot light's cone is sharp (θe = 0): the slack keeps a point on its very edge, which the
// direct light's own test lets through, from being bounded out by an angle's rounding.
constexpr double kSpotEdgeSlack = 1e-4;
// A united cone is widened by this much (radians): its half-angle comes from acos and a rotation,
// each a rounding off, and it must contain both cones it unites.
constexpr double kConeSlack = 1e-7;
// The cosine bounds are floored here once a point may be lit: a grazing emitter whose bound
// rounds to 0 keeps a probability above 0, as the estimate's unbiasedness needs.
constexpr double kLeastCosine = 1e-6;

double safeSqrt(double x) { return std::sqrt(std::max(0.0, x)); }
double safeAcos(double x) { return std::acos(std::clamp(x, -1.0, 1.0)); }

// cos(max(0, θa − θb)) and sin(max(0, θa − θb)) from the angles' sines and cosines.
double cosSubClamped(double sinA, double cosA, double sinB, double cosB) {
    return cosA > cosB ? 1.0 : cosA * cosB + sinA * sinB;
}
double sinSubClamped(double sinA, double cosA, double sinB, double cosB) {
    return cosA > cosB ? 0.0 : sinA * cosB - cosA * sinB;
}

// v rotated by `angle` about unit axis k (Rodrigues).
Vec3d rotate(const Vec3d& v, const Vec3d& k, double angle) {
    const double c = std::cos(angle), s = std::sin(angle);
    return v * c + cross(k, v) * s + k * (dot(k, v) * (1 - c));
}

// The cost of a node with bounds b split along `axis` (pbrt-v4's surface area orientation
// heuristic): power × the solid angle its cone may send into × its box's area, stretched for a
// box thin along the split axis.
double splitCost(const LightBounds& b, const Bounds3f& nodeBox, int axis) {
    const Vec3d d(b.box.diagonal());
    const double area = 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
    const Vec3d nodeDiagonal(nodeBox.diagonal());
    const double stretch = nodeDiagonal[axis] > 0 ? maxComponent(nodeDiagonal) / nodeDiagonal[axis] : 1.0;
    // The two cones most nodes have, without trigonometry: every direction (point lights), 4π;
    // one normal, Lambertian (a panel of lamps), π.
    if (b.cosTheta_o == -1) return b.phi * 4 * kPiD * stretch * area;
    if (b.cosTheta_o == 1 && b.cosTheta_e == 0) return b.phi * kPiD * stretch * area;
    const double thetaO = safeAcos(b.cosTheta_o), thetaE = safeAcos(b.cosTheta_e);
    const double thetaW = std::min(thetaO + thetaE, kPiD);
    const double sinO = safeSqrt(1 - b.cosTheta_o * b.cosTheta_o);
    const double solidAngle = 2 * kPiD * (1 - b.cosTheta_o) +
                              kPiD / 2 * (2 * thetaW * sinO - std::cos(thetaO - 2 * thetaW) - 2 * thetaO * sinO + b.cosTheta_o);
    return b.phi * solidAngle * stretch * area;
}

}  // namespace

LightBounds LightBounds::triangle(const Vec3f corner[3], const Vec3d& normal, double phi) {
    LightBounds b;
    for (int k = 0; k < 3; ++k) b.box.extend(corner[k]);
    b.phi = phi;
    b.area = 0.5 * length(cross(Vec3d(corner[1]) - Vec3d(corner[0]), Vec3d(corner[2]) - Vec3d(corner[0])));
    b.axis = normal;
    b.cosTheta_o = 1;
    b.cosTheta_e = 0;  // Lambertian: light leaves up to π/2 from the normal
    return b;
}

LightBounds LightBounds::point(const Vec3f& position, double phi) {
    LightBounds b;
    b.box.extend(position);
    b.phi = phi;
    b.cosTheta_o = -1;
    b.cosTheta_e = 0;
    return b;
}

LightBounds LightBounds::spot(const Vec3f& position, const Vec3d& direction, double cosOuter, double phi) {
    LightBounds b;
    b.box.extend(position);
    b.phi = phi;
    b.axis = direction;
    b.cosTheta_o = std::clamp(cosOuter, -1.0, 1.0);
    b.cosTheta_e = std::cos(kSpotEdgeSlack);
    return b;
}

LightBounds LightBounds::unite(const LightBounds& a, const LightBounds& b) {
    if (!(a.phi > 0)) return b;
    if (!(b.phi > 0)) return a;
    LightBounds u;
    u.box = a.box;
    u.box.extend(b.box);
    u.phi = a.phi + b.phi;
    u.area = a.area + b.area;
    u.cosTheta_e = std::min(a.cosTheta_e, b.cosTheta_e);
    // The smallest cone about both cones (pbrt-v4's DirectionCone::Union). Without a trigonometric
    // call where one cone is every direction (point lights) or both share an axis (a panel of
    // lamps): the tree's build unites every emitter into a bucket once per axis and level.
    if (a.cosTheta_o == -1 || b.cosTheta_o == -1) {
        u.axis = Vec3d(0, 0, 1);
        u.cosTheta_o = -1;
        return u;
    }
    if (a.axis == b.axis) {
        u.axis = a.axis;
        u.cosTheta_o = std::min(a.cosTheta_o, b.cosTheta_o);
        return u;
    }
    const double thetaA = safeAcos(a.cosTheta_o), thetaB = safeAcos(b.cosTheta_o);
    const double thetaD = safeAcos(dot(a.axis, b.axis));
    if (std::min(thetaD + thetaB, kPiD) <= thetaA) {
        u.axis = a.axis;
        u.cosTheta_o = a.cosTheta_o;
        return u;
    }
    if (std::min(thetaD + thetaA, kPiD) <= thetaB) {
        u.axis = b.axis;
        u.cosTheta_o = b.cosTheta_o;
        return u;
    }
    const double thetaO = (thetaA + thetaD + thetaB) / 2 + kConeSlack;
    const Vec3d k = cross(a.axis, b.axis);
    const double kLength = length(k);
    if (thetaO >= kPiD || !(kLength > 1e-12)) {
        u.axis = Vec3d(0, 0, 1);
        u.cosTheta_o = -1;
        return u;
    }
    u.axis = normalize(rotate(a.axis, k / kLength, thetaO - kConeSlack - thetaA));
    u.cosTheta_o = std::cos(thetaO);
    return u;
}

double LightBounds::importance(const Vec3d& p, const Vec3d& n) const {
    if (!(phi > 0)) return 0;
    const Vec3d lower(box.lower), upper(box.upper);
    const Vec3d centre = (lower + upper) * 0.5;
    const double radius2 = dot(upper - lower, upper - lower) * 0.25;
    const Vec3d toP = p - centre;
    // Exact for the box: light reaches p only from a point of the box in front of n, and a group of
    // emitters that all face one way (θo = 0, a lamp, a panel of lamps) lights only what lies in
    // front of some point of the box. A vertex on an emitter's own plane gets 0 from it here.
    const Vec3d half = (upper - lower) * 0.5;
    auto reach = [&](const Vec3d& a) { return std::abs(a.x) * half.x + std::abs(a.y) * half.y + std::abs(a.z) * half.z; };
    if (-dot(n, toP) + reach(n) <= 0) return 0;
    if (cosTheta_o == 1 && dot(axis, toP) + reach(axis) <= 0) return 0;
    const double d2 = dot(toP, toP);
    // Inside the box's bounding sphere every direction may bring light: no angle bounds it.
    if (d2 <= radius2) return phi / std::max(radius2, 1e-30);
    const double distance = std::sqrt(d2);
    const Vec3d wi = toP / distance;  // from the emitters toward p
    const double sinB = std::sqrt(radius2 / d2), cosB = safeSqrt(1 - radius2 / d2);

    // The emitters' side: the least angle between a direction they emit along and one toward p.
    double emitterCosine = 1;
    if (cosTheta_o > -1) {
        const double cosW = dot(axis, wi), sinW = safeSqrt(1 - cosW * cosW);
        const double sinO = safeSqrt(1 - cosTheta_o * cosTheta_o);
        const double cosX = cosSubClamped(sinW, cosW, sinO, cosTheta_o);
        const double sinX = sinSubClamped(sinW, cosW, sinO, cosTheta_o);
        emitterCosine = cosSubClamped(sinX, cosX, sinB, cosB);
        if (emitterCosine < cosTheta_e) return 0;
    }
    // p's side: the light must arrive from in front of n.
    const double cosI = -dot(n, wi), sinI = safeSqrt(1 - cosI * cosI);
    const double receiverCosine = cosSubClamped(sinI, cosI, sinB, cosB);
    if (receiverCosine < 0) return 0;
    return phi * std::max(emitterCosine, kLeastCosine) * std::max(receiverCosine, kLeastCosine) / d2;
}

LightTree::LightTree(const std::vector<LightBounds>& bounds) {
    std::vector<Item> items;
    for (uint32_t i = 0; i < bounds.size(); ++i)
        if (bounds[i].phi > 0) items.push_back({bounds[i], bounds[i].box.center(), i});
    leafOf_.assign(bounds.size(), std::numeric_limits<uint32_t>::max());
    positionOf_.assign(bounds.size(), 0);
    running_.assign(1, 0.0);
    if (items.empty()) return;
    nodes_.reserve(2 * items.size() - 1);
    build(items, 0, items.size(), -1, 0);
}

int32_t LightTree::build(std::vector<Item>& items, size_t first, size_t last, int32_t parent, int depth) {
    const int32_t index = int32_t(nodes_.size());
    nodes_.push_back({});
    nodes_[size_t(index)].parent = parent;
    nodes_[size_t(index)].first = uint32_t(order_.size());
    nodes_[size_t(index)].count = uint32_t(last - first);
    if (last - first == 1) {  // a leaf: one emitter
        const Item& item = items[first];
        nodes_[size_t(index)].bounds = item.bounds;
        positionOf_[item.emitter] = uint32_t(order_.size());
        order_.push_back(item.emitter);
        running_.push_back(running_.back() + item.bounds.phi);
        leafOf_[item.emitter] = uint32_t(index);
        return index;
    }
    Bounds3f centroids, nodeBox;
    for (size_t i = first; i < last; ++i) {
        centroids.extend(items[i].centre);
        nodeBox.extend(items[i].bounds.box);
    }
    // Bucketed surface area orientation heuristic over the three axes; deep in a degenerate tree
    // (coincident or exponentially spaced emitters) the count's median instead, which keeps the
    // depth, and so a sample's descent, within ~64 + log2(emitters).
    constexpr int kBuckets = 12;
    constexpr int kSahDepth = 48;
    double bestCost = std::numeric_limits<double>::infinity();
    int bestAxis = -1, bestSplit = 0;
    auto bucketOf = [&](const Item& item, int axis) {
        const double lo = centroids.lower[axis], hi = centroids.upper[axis];
        const int b = int(double(kBuckets) * (double(item.centre[axis]) - lo) / (hi - lo));
        return std::clamp(b, 0, kBuckets - 1);
    };
    if (depth < kSahDepth)
        for (int axis = 0; axis < 3; ++axis) {
            if (!(centroids.upper[axis] > centroids.lower[axis])) continue;
            std::array<LightBounds, kBuckets> bucket{};
            for (size_t i = first; i < last; ++i) {
                LightBounds& b = bucket[size_t(bucketOf(items[i], axis))];
                b = LightBounds::unite(b, items[i].bounds);
            }
            // The buckets up to each split and from it on, in one sweep each way.
            std::array<LightBounds, kBuckets> below{}, above{};
            below[0] = bucket[0];
            for (size_t k = 1; k < kBuckets; ++k) below[k] = LightBounds::unite(below[k - 1], bucket[k]);
            above[kBuckets - 1] = bucket[kBuckets - 1];
            for (size_t k = kBuckets - 1; k-- > 0;) above[k] = LightBounds::unite(bucket[k], above[k + 1]);
            for (int split = 0; split + 1 < kBuckets; ++split) {
                const LightBounds& b = below[size_t(split)];
                const LightBounds& a = above[size_t(split) + 1];
                if (!(b.phi > 0) || !(a.phi > 0)) continue;
                const double cost = splitCost(b, nodeBox, axis) + splitCost(a, nodeBox, axis);
                if (cost < bestCost) bestCost = cost, bestAxis = axis, bestSplit = split;
            }
        }
    const auto begin = items.begin() + long(first), end = items.begin() + long(last);
    size_t middle = first;
    if (bestAxis >= 0)
        middle = size_t(std::partition(begin, end, [&](const Item& item) { return bucketOf(item, bestAxis) <= bestSplit; }) -
                        items.begin());
    if (middle == first || middle == last) {
        // The count's median along the widest axis, ties broken by index: a fixed order.
        const Vec3f extent = centroids.diagonal();
        const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
        middle = (first + last) / 2;
        std::nth_element(begin, items.begin() + long(middle), end, [&](const Item& a, const Item& b) {
            return a.centre[axis] < b.centre[axis] || (a.centre[axis] == b.centre[axis] && a.emitter < b.emitter);
        });
    }
    build(items, first, middle, index, depth + 1);
    const int32_t second = build(items, middle, last, index, depth + 1);
    Node& node = nodes_[size_t(index)];
    node.second = second;
    node.bounds = LightBounds::unite(nodes_[size_t(index) + 1].bounds, nodes_[size_t(second)].bounds);
    // A panel: one facing, and its triangles cover most of its box's largest face.
    const Vec3d extent(node.bounds.box.diagonal());
    const double largestFace = std::max({extent.x * extent.y, extent.y * extent.z, extent.z * extent.x});
    node.panel = node.bounds.cosTheta_o == 1 && node.bounds.area >= kPanelFill * largestFace;
    if (node.panel) {
        // In the emitters' own order, as they were chosen by power before the tree: a panel that
        // is the whole scene's light (data/cornell's) is sampled as it was. (The nodes under it,
        // never descended into, keep ranges that no longer hold their emitters.)
        const auto begin = order_.begin() + long(node.first);
        std::sort(begin, begin + long(node.count));
        for (size_t at = node.first; at < size_t(node.first) + node.count; ++at) {
            const uint32_t e = order_[at];
            positionOf_[e] = uint32_t(at);
            running_[at + 1] = running_[at] + nodes_[leafOf_[e]].bounds.phi;  // its leaf's bounds are its own
        }
    }
    return index;
}

double LightTree::shareInNode(const Node& node, uint32_t emitter) const {
    const size_t k = positionOf_[emitter];
    return (running_[k + 1] - running_[k]) / (running_[node.first + node.count] - running_[node.first]);
}

bool LightTree::sample(const Vec3d& p, const Vec3d& n, double u, Choice& choice) const {
    if (nodes_.empty()) return false;
    size_t i = 0;
    double probability = 1;
    while (!seenWhole(nodes_[i])) {
        const size_t second = size_t(nodes_[i].second);
        const double a = nodes_[i + 1].bounds.importance(p, n), b = nodes_[second].bounds.importance(p, n);
        if (!(a + b > 0)) return false;
        const double pa = a / (a + b), pb = b / (a + b);
        if (u < pa) {
            i = i + 1;
            probability *= pa;
            u = u / pa;
        } else {
            i = second;
            probability *= pb;
            u = (u - pa) / pb;
        }
        u = std::min(u, std::nextafter(1.0, 0.0));
    }
    // Within the node by intensity: u's place in its emitters' running sum.
    const Node& node = nodes_[i];
    const double lo = running_[node.first], hi = running_[node.first + node.count];
    const double target = lo + u * (hi - lo);
    const auto begin = running_.begin() + long(node.first) + 1, end = begin + long(node.count);
    const size_t k = std::min(size_t(std::upper_bound(begin, end, target) - begin), size_t(node.count) - 1);
    const uint32_t emitter = order_[node.first + k];
    choice = {emitter, probability * shareInNode(node, emitter)};
    return true;
}

double LightTree::probability(const Vec3d& p, const Vec3d& n, uint32_t emitter) const {
    if (emitter >= leafOf_.size() || leafOf_[emitter] == std::numeric_limits<uint32_t>::max()) return 0;
    // The path from the root, then down it as sample() goes, to the node p sees whole.
    std::vector<uint32_t> path;
    for (int32_t node = int32_t(leafOf_[emitter]); node >= 0; node = nodes_[size_t(node)].parent) path.push_back(uint32_t(node));
    double probability = 1;
    for (size_t k = path.size(); k-- > 0;) {
        const Node& node = nodes_[path[k]];
        if (seenWhole(node)) return probability * shareInNode(node, emitter);
        const size_t second = size_t(node.second);
        const double a = nodes_[path[k] + 1].bounds.importance(p, n), b = nodes_[second].bounds.importance(p, n);
        if (!(a + b > 0)) return 0;
        probability *= (path[k - 1] == second ? b : a) / (a + b);
    }
    return probability;  // not reached: a leaf is seen whole
}

}  // namespace qsgi
