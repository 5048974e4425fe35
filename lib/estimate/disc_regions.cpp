#include "estimate/disc_regions.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bitset>
#include <cmath>
#include <optional>

#include "estimate/own_surface.h"
#include "estimate/own_surface_tree.h"
#include "scene/mesh_topology.h"

namespace qsgi {

bool VertexDisc::operator==(const VertexDisc& o) const {
    return tangent == o.tangent && bitangent == o.bitangent && start == o.start && epsAbove == o.epsAbove &&
           epsBelow == o.epsBelow && reachable == o.reachable && mixed == o.mixed && covered == o.covered &&
           mixedShare == o.mixedShare && reachableArea == o.reachableArea && fallback == o.fallback;
}

double VertexDisc::cellShare(int cell) const {
    if (reachable.test(cell)) return 1;
    if (!mixed.test(cell)) return 0;
    for (const auto& [c, share] : mixedShare)
        if (c == cell) return share / 16.0;
    return 0;
}

double VertexDisc::coveredArea(double s) const {
    if (covered.count() == kDiscCells) return M_PI * s * s;
    std::array<double, kDiscRings> ringShare{};
    for (int c = 0; c < kDiscCells; ++c)
        if (covered.test(c)) ringShare[discRingOf(c)] += cellShare(c) / kDiscSectors;
    return discAreaWithin(ringShare, s);
}

namespace {
// The segment from s_v to a lifted point of the disc meets no geometry.
bool segmentClear(const Vec3d& start, const Vec3d& target, const SceneBvh& bvh) {
    const Vec3d d = target - start;
    const double len = length(d);
    return !(len > 0) || !bvh.occluded(Vec3f(start), Vec3f(d / len), 0.0f, float(len));
}

Vec3d liftedDiscPoint(const VertexDisc& disc, const Vec3f& centre, const Vec3f& normal, float radius, double x, double y) {
    return Vec3d(centre) + (Vec3d(disc.tangent) * x + Vec3d(disc.bitangent) * y) * double(radius) +
           Vec3d(normal) * double(disc.epsAbove);
}
}  // namespace

bool discPointReachable(const VertexDisc& disc, const Vec3f& centre, const Vec3f& normal, float radius, double x,
                        double y, const SceneBvh& bvh) {
    return segmentClear(Vec3d(disc.start), liftedDiscPoint(disc, centre, normal, radius, x, y), bvh);
}

bool pointReachable(Reach reach, const VertexDisc& disc, const Vec3f& centre, const Vec3f& normal, float radius,
                    double x, double y, const SceneBvh* bvh) {
    if (reach != Reach::TestPoint) return reach == Reach::Yes;
    return bvh && discPointReachable(disc, centre, normal, radius, x, y, *bvh);
}

namespace {

// Where a corner's and a cell centre's answers sit in StaticAnswers (ring 0's corners are v).
constexpr int cornerSlot(int ring, int sector) { return (ring - 1) * kDiscSectors + sector; }
constexpr int centreSlot(int cell) { return kDiscRings * kDiscSectors + cell; }

// What a disc's rays may skip asking the static BVH, every answer being the one it would give.
struct StaticShortcuts {
    bool nothingNear = false;  // no static triangle near rises to the disc's rays: all clear
    DiscRegions::StaticAnswers* answers = nullptr;  // where corner and centre answers are kept
    bool reuse = false;  // read them from there (kept for this very start and lift)
    DiscRegions::Work* tally = nullptr;  // counts the rays traced
};

// The cells of v's disc that light can reach from `startPoint` (docs/design.md §5).
VertexDisc discFrom(const Vec3f& startPoint, VertexDisc disc, uint32_t v, const Scene& scene, const SceneBvh& bvh,
                    const std::vector<Vec3f>& frontNormals, float radius, bool withCoverage, const OwnSurface& own,
                    const StaticShortcuts& shortcuts) {
    const Vec3f& normal = scene.normals[v];
    disc.start = startPoint;
    const Vec3d start(disc.start);
    const Vec3f& centre = scene.positions[v];
    const DiscPatternPoints& points = discPatternPoints();
    // The ray from s_v toward a lifted point of the disc (none if the point is s_v itself).
    struct Ray {
        Vec3f origin, direction;
        float length;
    };
    auto rayTo = [&](double x, double y) -> std::optional<Ray> {
        const Vec3d d = liftedDiscPoint(disc, centre, normal, radius, x, y) - start;
        const double len = length(d);
        if (!(len > 0)) return std::nullopt;
        return Ray{Vec3f(start), Vec3f(d / len), float(len)};
    };
    // Whether the static geometry leaves each of `count` rays clear (no ray: clear), told to
    // setClear(k, clear): sixteen rays to a packet, as they all start at s_v.
    auto staticallyClear = [&](const std::optional<Ray>* rays, int count, auto&& setClear) {
        SceneBvh::RayPacket packet;
        int slots[SceneBvh::RayPacket::kMaxRays];
        auto flush = [&] {
            const uint32_t blocked = bvh.staticOccludesPacket(packet);
            shortcuts.tally->rays += uint64_t(packet.count);
            for (int i = 0; i < packet.count; ++i) setClear(slots[i], !(blocked >> i & 1));
            packet.count = 0;
        };
        for (int k = 0; k < count; ++k) {
            if (!rays[k] || shortcuts.nothingNear) {
                setClear(k, true);
                continue;
            }
            slots[packet.count] = k;
            packet.add(rays[k]->origin, rays[k]->direction, rays[k]->length);
            if (packet.count == SceneBvh::RayPacket::kMaxRays) flush();
        }
        flush();
    };
    // The rays to every corner (rings 1…16) and cell centre, by answer slot, made once.
    std::array<std::optional<Ray>, size_t(2 * kDiscCells)> rays;
    for (int slot = 0; slot < 2 * kDiscCells; ++slot) {
        const auto& p = slot < kDiscCells ? points.corners[size_t(slot + kDiscSectors)] : points.centres[size_t(slot - kDiscCells)];
        rays[size_t(slot)] = rayTo(p.x, p.y);
    }
    // Their static answers, kept or asked now.
    std::bitset<size_t(2 * kDiscCells)> staticClear;
    if (shortcuts.reuse) {
        staticClear = shortcuts.answers->clear;
    } else {
        staticallyClear(rays.data(), 2 * kDiscCells, [&](int slot, bool clear) { staticClear.set(size_t(slot), clear); });
        if (shortcuts.answers) shortcuts.answers->clear = staticClear;
    }
    // segmentClear: the static half as asked above, the dynamic half now.
    auto clearAfterStatic = [&](const std::optional<Ray>& ray, bool isStaticallyClear) {
        return !ray || (isStaticallyClear && !bvh.dynamicOccludes(ray->origin, ray->direction, 0.0f, ray->length));
    };
    auto slotClear = [&](int slot) { return clearAfterStatic(rays[size_t(slot)], staticClear.test(size_t(slot))); };
    // Corners of the polar cells (shared between neighbours): ring boundaries × sector boundaries.
    std::array<uint8_t, size_t(kDiscRings + 1) * kDiscSectors> cornerClear;
    for (int i = 0; i <= kDiscRings; ++i)
        for (int j = 0; j < kDiscSectors; ++j) {
            const size_t k = size_t(i) * kDiscSectors + size_t(j);
            cornerClear[k] = i == 0 ? 1 : slotClear(cornerSlot(i, j));
        }
    double share = 0;
    for (int c = 0; c < kDiscCells; ++c) {
        const int ring = c / kDiscSectors, sector = c % kDiscSectors, next = (sector + 1) % kDiscSectors;
        const double x = points.centres[size_t(c)].x, y = points.centres[size_t(c)].y;
        const bool centreClear = slotClear(centreSlot(c));
        // The centre of ring 0's corners is v itself: its own side, reachable by construction.
        const uint8_t corners[4] = {cornerClear[size_t(ring) * kDiscSectors + size_t(sector)],
                                    cornerClear[size_t(ring) * kDiscSectors + size_t(next)],
                                    cornerClear[size_t(ring + 1) * kDiscSectors + size_t(sector)],
                                    cornerClear[size_t(ring + 1) * kDiscSectors + size_t(next)]};
        bool uniform = true;
        for (int k = ring == 0 ? 2 : 0; k < 4; ++k) uniform = uniform && bool(corners[k]) == centreClear;
        if (uniform) {
            if (!centreClear) continue;
            disc.reachable.set(c);
            share += 1;
        } else {
            const auto& subPoints = points.subPoints[size_t(c)];
            std::array<std::optional<Ray>, 16> subRays;
            for (size_t k = 0; k < subPoints.size(); ++k) subRays[k] = rayTo(subPoints[k].x, subPoints[k].y);
            uint32_t subClear = 0;
            staticallyClear(subRays.data(), int(subRays.size()), [&](int k, bool clear) { subClear |= uint32_t(clear) << k; });
            int clearSubPoints = 0;
            for (size_t k = 0; k < subRays.size(); ++k) clearSubPoints += clearAfterStatic(subRays[k], subClear >> k & 1);
            disc.mixed.set(c);
            disc.mixedShare.emplace_back(uint8_t(c), uint8_t(clearSubPoints));
            share += clearSubPoints / 16.0;
        }
        if (!withCoverage || !(centreClear || disc.mixed.test(c))) continue;
        // Probe straight down through the band [−ε⁻, ε⁺] for a surface facing n_v.
        const Vec3d lifted = liftedDiscPoint(disc, centre, normal, radius, x, y);
        const auto hit = bvh.intersect(Vec3f(lifted), -normal, 0.0f, own.epsAbove + own.epsBelow);
        ++shortcuts.tally->rays;
        if (hit && dot(frontNormals[hit->triangle], normal) > kOwnSurfaceCos) disc.covered.set(c);
    }
    disc.reachableArea = float(share / kDiscCells);
    return disc;
}

// The mean count of triangles in the own surfaces of 256 of the vertices, evenly spaced: what a
// walk costs here.
double meanOwnSurfaceTriangles(const Scene& scene, const MeshTopology& topology, const std::vector<Vec3f>& frontNormals,
                               const std::vector<uint32_t>& vertices, float radius) {
    constexpr size_t kSample = 256;
    const size_t step = std::max<size_t>(1, vertices.size() / kSample);
    OwnSurfaceScratch scratch;
    OwnSurfaceQuery walk;
    walk.depthBelow = false;
    uint64_t triangles = 0, walked = 0;
    for (size_t i = 0; i < vertices.size(); i += step, ++walked)
        triangles += findOwnSurface(vertices[i], scene, topology, frontNormals, radius, scratch, walk).trianglesWalked;
    return walked ? double(triangles) / double(walked) : 0;
}

VertexDisc computeVertexDisc(uint32_t v, const Scene& scene, const SceneBvh& bvh, const MeshTopology& topology,
                             const std::vector<Vec3f>& frontNormals, float radius, bool withCoverage,
                             OwnSurfaceScratch& scratch, const OwnSurfaceTree* tree, bool treeForOwnSurface, DiscRegions::Work& tally,
                             DiscRegions::StaticAnswers* answers, bool staticShortcut) {
    VertexDisc disc;
    const Vec3f& normal = scene.normals[v];
    discFrame(normal, disc.tangent, disc.bitangent);
    // Only the photon map's coverage reads ε_v⁻; without it the search may stop early.
    OwnSurfaceQuery query;
    query.depthBelow = withCoverage;
    query.tree = treeForOwnSurface ? tree : nullptr;
    const OwnSurface own = findOwnSurface(v, scene, topology, frontNormals, radius, scratch, query);
    tally.ownSurfacesProved += own.provedByTree;
    if (own.empty) {
        disc.fallback = true;
        return disc;
    }
    disc.epsAbove = own.epsAbove;
    disc.epsBelow = own.epsBelow;
    // Double precision for the points, so the float rays start exactly where the rule says.
    const double sideStep = std::min(1e-3 * double(radius), double(scene.sceneEpsilon()));
    const Vec3d lifted = Vec3d(scene.positions[v]) + Vec3d(normal) * double(own.epsAbove);
    const Vec3f start(lifted + Vec3d(own.towardSurface) * sideStep);
    // The starts tried below: s_v, and if nothing is reachable from it, a step to each side.
    const Vec3d sides[4] = {Vec3d(disc.tangent), -Vec3d(disc.tangent), Vec3d(disc.bitangent), -Vec3d(disc.bitangent)};
    Vec3f sideStarts[4];
    for (int k = 0; k < 4; ++k) sideStarts[k] = Vec3f(lifted + sides[k] * sideStep);
    StaticShortcuts shortcuts;
    shortcuts.tally = &tally;
    // Every ray of the disc (from any of those starts) stays within r + ε⁺ + the side step of v,
    // at about the height ε⁺ above v's tangent plane: the starts step sideways from v lifted by
    // ε⁺ (toward the own surface, or along the tangents), and the disc's points are lifted by ε⁺.
    // Static triangles whose corners all stay below the lowest of those heights, as the own
    // surface of a flat or convex patch does, cannot block them: when no other static triangle is
    // near, every static answer is "clear". The heights are those of the float starts as made;
    // the margin below them covers what the rays' floats add (the disc's points and directions
    // rounded, over coordinates as large as v's and lengths of about r) and Embree's own
    // rounding, with room to spare (2^-20 of those; the rounding is near 2^-24). Where the
    // margin eats all of ε⁺ (a scene far from its origin) the rays are asked, as always.
    if (staticShortcut) {
        const Vec3d p(scene.positions[v]), n(normal);
        double lowest = double(own.epsAbove) * dot(n, n);
        for (const Vec3f& s : sideStarts) lowest = std::min(lowest, dot(Vec3d(s) - p, n));
        lowest = std::min(lowest, dot(Vec3d(start) - p, n));
        const double margin = std::ldexp(std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) + double(radius) +
                                             double(own.epsAbove),
                                         -20);
        const Vec3f& centre = scene.positions[v];
        const float reach = float(double(radius) + double(own.epsAbove) + sideStep) + bvh.rayEpsilon();
        const double height = lowest - margin;
        // The same question, asked of the tree where there is one (it prunes what cannot rise;
        // Embree's point query visits every triangle near), with the same limit on static
        // triangles looked at, past which both say "rises" and the rays are traced.
        uint32_t looked = 0;
        shortcuts.nothingNear =
            tree ? !tree->anyRising(OwnSurfaceTree::kAnyPiece, Vec3d(centre), n, -2.0, double(reach), height,
                                    [&](uint32_t tri) {
                                        if (scene.triangleDynamic[tri]) return false;
                                        if (++looked > SceneBvh::kMostTrianglesNear) return true;
                                        const Triangle& T = scene.triangles[tri];
                                        const Vec3f corners[3] = {scene.positions[T.v[0]], scene.positions[T.v[1]],
                                                                  scene.positions[T.v[2]]};
                                        return triangleRisesNear(corners, centre, reach, n, height);
                                    })
                 : !bvh.staticGeometryRises(centre, reach, normal, height);
        tally.staticRaysSkipped += shortcuts.nothingNear;
    }
    // The kept answers hold while the rays are the same: same start and lift (a static vertex's
    // own surface is static, unless a moved vertex now welds onto it).
    StaticShortcuts primary = shortcuts;
    primary.answers = answers;
    primary.reuse = answers && answers->valid && answers->start == start && answers->epsAbove == own.epsAbove;
    if (answers && !primary.reuse) {
        answers->valid = true;
        answers->start = start;
        answers->epsAbove = own.epsAbove;
    }
    VertexDisc best = discFrom(start, disc, v, scene, bvh, frontNormals, radius, withCoverage, own, primary);
    if (best.reachableArea > 0) return best;
    // Nothing reachable from the start point: either v is buried, or the start lies exactly on a
    // surface through v (a floor vertex at the foot of a wall, where the own surface runs on under
    // the wall and gives no side to step to), and which side of it float rounding puts the start
    // on decides everything — the answer would change with the scene's unit. Light reaching v
    // comes from the open side, so try a step to each side and keep the one that sees most —
    // of those outside closed geometry first: a step into a block standing on the line (a floor
    // vertex on its foot) "reaches" the cells under the block through the block's inside, and may
    // tie with the step outward. A start is inside when a ray from it along any of the four side
    // directions, two steps long, first meets a back face: the step that crossed the block's wall
    // sees it from behind on the way back, and so does a step along the wall from a lifted point
    // that rounding put a hair inside. The rays stay within three side steps of v, inside the
    // region a move's recompute covers (touchedBy), so an update decides as a full one does.
    bool bestOutside = false;
    for (const Vec3f& sideStart : sideStarts) {
        VertexDisc candidate = discFrom(sideStart, disc, v, scene, bvh, frontNormals, radius, withCoverage, own, shortcuts);
        if (!(candidate.reachableArea > 0)) continue;
        bool outside = true;
        for (const Vec3d& side : sides) {
            const Vec3f direction(side);
            const auto hit = bvh.intersect(sideStart, direction, 0.0f, float(2 * sideStep));
            ++tally.rays;
            if (hit && dot(frontNormals[hit->triangle], direction) > 0) outside = false;
        }
        if (outside != bestOutside ? outside : candidate.reachableArea > best.reachableArea) {
            best = std::move(candidate);
            bestOutside = outside;
        }
    }
    return best;
}

}  // namespace

void DiscRegions::computeAll(const Scene& scene, const SceneBvh& bvh, WorkCounter* progress) {
    discs_.assign(scene.vertexCount(), VertexDisc{});
    answerSlot_.clear();
    answers_.clear();
    std::vector<uint32_t> all(scene.vertexCount());
    for (uint32_t v = 0; v < all.size(); ++v) all[v] = v;
    compute(scene, bvh, all, false, progress);
}

std::vector<uint32_t> DiscRegions::recompute(const Scene& scene, const SceneBvh& bvh, const std::vector<uint32_t>& vertices,
                                             WorkCounter* progress) {
    return compute(scene, bvh, vertices, true, progress);
}

std::vector<uint32_t> DiscRegions::compute(const Scene& scene, const SceneBvh& bvh, const std::vector<uint32_t>& vertices,
                                           bool keepAnswers, WorkCounter* progress) {
    if (progress) progress->setTotal(vertices.size());
    if (discs_.size() != scene.vertexCount()) discs_.resize(scene.vertexCount());
    lastWork_ = Work();
    if (vertices.empty()) return {};
    if (keepAnswers) {
        // A record per vertex a move has touched: the touchable set is small beside the scene.
        answerSlot_.resize(scene.vertexCount(), -1);
        for (uint32_t v : vertices)
            if (answerSlot_[v] < 0) {
                answerSlot_[v] = int32_t(answers_.size());
                answers_.emplace_back();
            }
    }
    std::vector<uint8_t> changed(vertices.size(), 0);
    const MeshTopology topology(scene);
    const std::vector<Vec3f> frontNormals = scene.frontFaceNormals();
    // The tree pays where own surfaces hold many triangles — a dense mesh, where walking them or
    // visiting every triangle near (Embree's point query) is what costs — and costs about what
    // walking the own surfaces of a few vertices in a hundred does: it is built for a frame's
    // worth of vertices whose own surfaces, sampled, hold 64 triangles or more on average. Where
    // they hold fewer (data/cornell: about 20; 2CylinderEngine, whose parts crowd the tree's
    // nodes) the walk is the cheaper way. The answers are the same either way.
    std::optional<OwnSurfaceTree> tree;
    const bool treeAsked = ownSurfaceShortcut_ || staticShortcut_;
    const bool treePays = treeAsked && treeUse_ == TreeUse::WhereItPays && vertices.size() * 16 >= scene.triangleCount() &&
                          meanOwnSurfaceTriangles(scene, topology, frontNormals, vertices, radius_) >= 64;
    if (treeAsked && (treeUse_ == TreeUse::Always || treePays)) tree.emplace(scene, frontNormals, topology);
    // Each vertex depends on nothing but the geometry: any schedule gives the same bytes.
    tbb::enumerable_thread_specific<OwnSurfaceScratch> scratch;
    tbb::enumerable_thread_specific<Work> tallies;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices.size(), 32), [&](const tbb::blocked_range<size_t>& range) {
        OwnSurfaceScratch& local = scratch.local();
        Work& tally = tallies.local();
        for (size_t i = range.begin(); i != range.end(); ++i) {
            StaticAnswers* answers = keepAnswers ? &answers_[size_t(answerSlot_[vertices[i]])] : nullptr;
            if (answers && scene.vertexDynamic[vertices[i]]) answers = nullptr;
            VertexDisc disc = computeVertexDisc(vertices[i], scene, bvh, topology, frontNormals, radius_, withCoverage_, local,
                                                tree ? &*tree : nullptr, ownSurfaceShortcut_, tally, answers, staticShortcut_);
            changed[i] = !(disc == discs_[vertices[i]]) || disc.mixed.count() > 0;
            discs_[vertices[i]] = std::move(disc);
        }
        if (progress) progress->add(range.size());
    });
    for (const Work& t : tallies) lastWork_ += t;
    std::vector<uint32_t> out;
    for (size_t i = 0; i < vertices.size(); ++i)
        if (changed[i]) out.push_back(vertices[i]);
    return out;
}

std::vector<uint32_t> DiscRegions::touchedBy(const Scene& scene, const std::vector<Bounds3f>& movedBounds,
                                             const std::vector<uint8_t>& vertexMoved) const {
    // The test region (cylinder of radius r, |h| ≤ r; the reachability segments and probes stay
    // inside it) lies within r·√2 of v; the scene epsilon covers the lift of the start point.
    const float reach = radius_ * 1.41421357f + 4 * scene.sceneEpsilon();
    std::vector<uint32_t> touched;
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        bool hit = v < vertexMoved.size() && vertexMoved[v];
        if (!hit) {
            Bounds3f region;
            region.extend(scene.positions[v]);
            region = region.expanded(reach);
            for (const Bounds3f& b : movedBounds) hit = hit || region.overlaps(b);
        }
        if (hit) touched.push_back(v);
    }
    return touched;
}

uint64_t DiscRegions::fallbackVertices() const {
    return uint64_t(std::count_if(discs_.begin(), discs_.end(), [](const VertexDisc& d) { return d.fallback; }));
}

uint64_t DiscRegions::buriedVertices() const {
    return uint64_t(std::count_if(discs_.begin(), discs_.end(), [](const VertexDisc& d) { return !d.fallback && !(d.reachableArea > 0); }));
}

uint64_t DiscRegions::mixedCells() const {
    uint64_t n = 0;
    for (const VertexDisc& d : discs_) n += uint64_t(d.mixed.count());
    return n;
}

}  // namespace qsgi
