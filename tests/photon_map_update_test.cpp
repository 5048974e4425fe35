// The photon map follows a changing photon set (docs/design.md §6.4): after update() its estimates equal,
// bit for bit, those of a map built from scratch over the same impacts and those of brute force;
// and recomputing only the vertices ballsHolding() names, or those whose neighbour lists
// editLists() edits, gives the full estimate of the new set.
// Ties (equal distances) occur on purpose: some added impacts copy a live one exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

#include "estimate/disc_regions.h"
#include "estimate/photon_map.h"
#include "test_support.h"
#include "trace/embree_device.h"
#include "trace/scene_bvh.h"

using namespace qsgi;

namespace {

bool sameBits(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3f)) == 0;
}

size_t differing(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    size_t n = 0;
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) n += std::memcmp(&a[i], &b[i], sizeof(Vec3f)) != 0;
    return n;
}

uint64_t keyOf(const Segment& s) { return uint64_t(s.path) << 16 | s.bounce; }

Scene litBoxOnFloor() {
    Scene s = testscenes::boxOnFloor(32, 8, Vec3f(0.6f));
    testscenes::addPointLight(s, Vec3f(0.2f, 1.5f, 0.1f), Vec3f(10.0f));
    return s;
}

// A traced cache, the live part of it plus made-up segments, and a deterministic change per round.
// `spread` sets how much changes: path tails leave for one path in `spread` and come back for one
// in `spread + 2`; one live impact in `2 * spread - 1` is copied twice (exactly, a tie; and 1 cm
// along its surface, inside the neighbouring vertices' balls). Each round also adds, beside one
// floor vertex:
// - a dense cluster of impacts from below (they count for no floor vertex) ringed by a few from
//   above: the added impacts' tree holds more near, uncounted ones than a query first asks for,
//   and the counted ones lie beyond them;
// - a stack of coincident impacts from above, more than a query first asks for: a tree returns an
//   arbitrary part of a tie at its farthest distance, and the keys must decide.
class ChangingPhotons {
public:
    struct Change {
        std::vector<Segment> removed, added;
    };

    ChangingPhotons(const RayCache& full, const Scene& scene, int spread)
        : maxPhotonPower_(full.maxPhotonPower), paths_(full.pathCount()), segments_(full.decodeAll()),
          front_(scene.frontFaceNormals()), spread_(size_t(spread)) {
        pathBegin_.assign(paths_ + 1, segments_.size());
        for (size_t i = segments_.size(); i-- > 0;) pathBegin_[segments_[i].path] = i;
        for (size_t p = paths_; p-- > 0;) pathBegin_[p] = std::min(pathBegin_[p], pathBegin_[p + 1]);
        float floorY = scene.positions[0].y;  // positions are re-centred on the scene
        for (const Vec3f& p : scene.positions) floorY = std::min(floorY, p.y);
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3f p = scene.positions[v];
            if (p.y == floorY && scene.normals[v].y > 0.9f && std::fabs(p.x) < 1.5f && std::fabs(p.z) < 1.5f)
                floorVertices_.push_back(p);
        }
        for (uint32_t t = 0; t < front_.size() && floorTriangle_ == kNoTriangle; ++t)
            if (front_[t].y > 0.9f) floorTriangle_ = t;
        // At the start a quarter of the paths miss their tail from bounce 1 on.
        for (size_t p = 0; p < paths_; ++p)
            for (uint64_t i = pathBegin_[p]; i < pathBegin_[p + 1]; ++i)
                if (p % 4 != 1 || segments_[i].bounce < 1) live_[keyOf(segments_[i])] = segments_[i];
    }

    RayCache liveCache() const {
        std::vector<Segment> live;
        for (const auto& [key, s] : live_) live.push_back(s);
        // Not in key order: the map may not rely on the order it is given.
        std::reverse(live.begin(), live.end());
        return RayCache::ofSegments(std::move(live), maxPhotonPower_);
    }

    Change next(size_t round) {
        Change c;
        const size_t paths = paths_;
        // Made-up segments leave (half of those live), from the small tree or the big one.
        for (const auto& [key, s] : live_)
            if (s.path >= kMadeUp && (s.path + round) % 2 == 0) c.removed.push_back(s);
        // Tails leave: from bounce (p / spread) % 3 on.
        for (size_t p = round % spread_; p < paths; p += spread_)
            for (uint64_t i = pathBegin_[p]; i < pathBegin_[p + 1]; ++i) {
                const Segment& s = segments_[i];
                if (s.bounce >= (p / spread_) % 3 && live_.count(keyOf(s))) c.removed.push_back(s);
            }
        // Missing tails come back (some left just above: the same keys return, as a retrace does).
        std::unordered_set<uint64_t> leaving;
        for (const Segment& s : c.removed) leaving.insert(keyOf(s));
        for (size_t p = round % (spread_ + 2); p < paths; p += spread_ + 2)
            for (uint64_t i = pathBegin_[p]; i < pathBegin_[p + 1]; ++i) {
                const Segment& s = segments_[i];
                if (!live_.count(keyOf(s)) || leaving.count(keyOf(s))) c.added.push_back(s);
            }
        // Made-up impacts beside and on top of live ones.
        const size_t stride = 2 * spread_ - 1;
        size_t n = 0;
        for (const auto& [key, s] : live_) {
            if (!s.hasImpact() || s.path >= kMadeUp || n++ % stride != round % stride) continue;
            Segment tie = s;
            tie.path = nextPath_++;
            tie.bounce = 0;
            tie.scattered = 0;
            tie.power = s.power * 0.5f;  // choosing the wrong one of a tie changes the sum
            c.added.push_back(tie);
            const Vec3f normal = front_[s.triangle];
            const Vec3f side = normalize(cross(normal, std::fabs(normal.x) < 0.9f ? Vec3f(1, 0, 0) : Vec3f(0, 1, 0)));
            Segment beside = s;
            beside.path = nextPath_++;
            beside.bounce = 1;
            beside.scattered = 1;
            beside.origin = s.origin + side * (n % 2 ? 0.01f : -0.01f);
            beside.power = s.power * 1.5f;
            c.added.push_back(beside);
        }
        const Vec3f centre = floorVertices_[(round * 131 + 17) % floorVertices_.size()] + Vec3f(0.02f, 0, 0.01f);
        const Vec3f power = segments_.front().power * 0.25f;
        const auto madeUp = [&](Vec3f at, bool fromAbove) {
            Segment s;
            s.direction = Vec3f(0, fromAbove ? -1.0f : 1.0f, 0);
            s.origin = at - s.direction * 0.5f;
            s.length = 0.5f;
            s.power = power;
            s.triangle = floorTriangle_;
            s.path = nextPath_++;
            c.added.push_back(s);
        };
        for (int i = -5; i <= 5; ++i)
            for (int j = -6; j <= 6; ++j) madeUp(centre + Vec3f(0.001f * float(i), 0, 0.001f * float(j)), false);
        for (int a = 0; a < 12; ++a)
            madeUp(centre + Vec3f(std::cos(0.5236f * float(a)), 0, std::sin(0.5236f * float(a))) * 0.008f, true);
        for (int i = 0; i < 110; ++i) {
            madeUp(centre + Vec3f(0.01f, 0, -0.03f), true);
            c.added.back().power = power * (1.0f + 0.1f * float(i % 7));
        }
        for (const Segment& s : c.removed) live_.erase(keyOf(s));
        for (const Segment& s : c.added) live_[keyOf(s)] = s;
        return c;
    }

    size_t liveImpacts() const {
        size_t n = 0;
        for (const auto& [key, s] : live_) n += s.hasImpact();
        return n;
    }

private:
    static constexpr uint32_t kMadeUp = 1u << 24;  // beyond the traced paths
    float maxPhotonPower_;
    size_t paths_;
    std::vector<Segment> segments_;   // the traced cache's, decoded
    std::vector<uint64_t> pathBegin_;  // path p owns segments_[pathBegin_[p], pathBegin_[p + 1])
    std::vector<Vec3f> front_;
    size_t spread_;
    std::vector<Vec3f> floorVertices_;
    uint32_t floorTriangle_ = kNoTriangle;
    std::map<uint64_t, Segment> live_;
    uint32_t nextPath_ = kMadeUp;
};

struct EstimateCase {
    int k;
    float radius;
    bool regions;  // the `clip` rule's own-surface filter; without: the textbook rule
    std::string name() const {
        return "k = " + std::to_string(k) + ", r = " + std::to_string(radius) + (regions ? ", regions" : ", textbook");
    }
};

// k = 50 and k = 4, each with a radius that leaves some vertices fewer than k impacts.
const EstimateCase kCases[] = {{50, 0.15f, true}, {50, 0.15f, false}, {4, 0.04f, true}, {4, 0.04f, false}};

struct Fixture {
    Scene scene = litBoxOnFloor();
    EmbreeDevice device;
    SceneBvh bvh{device, scene};
    RayCache full = traceScene(scene, 20000, 7);
    std::vector<uint32_t> all, reversed;
    Fixture() {
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) all.push_back(v);
        reversed.assign(all.rbegin(), all.rend());
    }
    DiscRegions regionsFor(float radius) const {
        DiscRegions r(radius, true);
        r.computeAll(scene, bvh);
        return r;
    }
};

// Vertices with fewer than k front-facing impacts within the radius, and with at least k.
std::pair<size_t, size_t> fewerAndMore(const Scene& scene, const RayCache& cache, float radius, int k) {
    size_t fewer = 0;
    for (size_t v = 0; v < scene.vertexCount(); ++v) {
        int n = 0;
        cache.forEachSegment([&](const Segment& s) {
            n += s.hasImpact() && dot(s.direction, scene.normals[v]) < 0 &&
                 PointIndex::distanceSquared(scene.positions[v], s.impactPoint()) <= radius * radius;
        });
        fewer += n < k;
    }
    return {fewer, scene.vertexCount() - fewer};
}

}  // namespace

// Rounds of removals and additions; after each, the updated map's estimate at every vertex (in
// reverse order) equals a new map's over the same impacts and brute force's, to the bit.
TEST(PhotonMapUpdate, UpdatedMapEqualsNewMapAndBruteForce) {
    Fixture f;
    for (const EstimateCase& e : kCases) {
        SCOPED_TRACE(e.name());
        const DiscRegions covered = f.regionsFor(e.radius);
        const DiscRegions* regions = e.regions ? &covered : nullptr;
        ChangingPhotons photons(f.full, f.scene, 7);
        if (!e.regions) {
            const auto [fewer, more] = fewerAndMore(f.scene, photons.liveCache(), e.radius, e.k);
            EXPECT_GT(fewer, 50u);
            EXPECT_GT(more, 50u);
        }
        PhotonMap map(photons.liveCache(), f.scene, &f.bvh);
        for (size_t round = 0; round < 5; ++round) {
            const ChangingPhotons::Change change = photons.next(round);
            map.update(change.removed, change.added, f.scene);
            ASSERT_EQ(map.size(), photons.liveImpacts());
            std::vector<Vec3f> updated;
            map.irradianceAt(f.scene, regions, e.radius, e.k, f.reversed, updated);
            const PhotonMap fresh(photons.liveCache(), f.scene, &f.bvh);
            const auto expected = fresh.irradiance(f.scene, regions, e.radius, e.k, f.all);
            EXPECT_TRUE(sameBits(updated, expected)) << "round " << round << ": " << differing(updated, expected) << " differ";
            EXPECT_TRUE(sameBits(map.bruteForce(f.scene, regions, e.radius, e.k), expected)) << "round " << round;
        }
    }
}

// After each round only the vertices whose previous ball holds a removed or added impact are
// re-estimated; the others keep their values. The result equals a full estimate of the new set.
TEST(PhotonMapUpdate, RecomputingTheBallsHoldingAChangeEqualsAFullEstimate) {
    Fixture f;
    for (const EstimateCase& e : kCases) {
        SCOPED_TRACE(e.name());
        const DiscRegions covered = f.regionsFor(e.radius);
        const DiscRegions* regions = e.regions ? &covered : nullptr;
        ChangingPhotons photons(f.full, f.scene, 151);  // a few per cent of the impacts change per round
        PhotonMap map(photons.liveCache(), f.scene, &f.bvh);
        std::vector<Vec3f> current = map.irradiance(f.scene, regions, e.radius, e.k, f.all);
        size_t recomputed = 0, changed = 0;
        for (size_t round = 0; round < 6; ++round) {
            const ChangingPhotons::Change change = photons.next(round);
            std::vector<uint32_t> vertices = map.ballsHolding(f.scene, regions, change.removed);
            map.update(change.removed, change.added, f.scene);
            const std::vector<uint32_t> entered = map.ballsHolding(f.scene, regions, change.added);
            vertices.insert(vertices.end(), entered.begin(), entered.end());
            std::sort(vertices.begin(), vertices.end());
            vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
            ASSERT_TRUE(std::is_sorted(vertices.begin(), vertices.end()));
            ASSERT_TRUE(std::adjacent_find(vertices.begin(), vertices.end()) == vertices.end());
            const std::vector<Vec3f> before = current;
            map.irradianceAt(f.scene, regions, e.radius, e.k, vertices, current);
            const auto expected = PhotonMap(photons.liveCache(), f.scene, &f.bvh).irradiance(f.scene, regions, e.radius, e.k, f.all);
            EXPECT_TRUE(sameBits(current, expected)) << "round " << round << ": " << differing(current, expected) << " differ";
            recomputed += vertices.size();
            changed += differing(before, expected);
        }
        // The test means something: estimates changed, and fewer than half were recomputed.
        EXPECT_GT(changed, 0u);
        EXPECT_LT(recomputed, 6 * f.scene.vertexCount() / 2);
    }
}

// With neighbour lists (what an animation's frames use), a change edits the lists that hold its
// impacts, and only the vertices editLists() names are estimated again — from their lists, or by
// a fresh query where a list fell short. The result equals a full estimate of the new set, round
// after round, ties and impacts beside uncounted clusters included. Checked once by breaking it:
// leaving the added impacts out of the lists makes every case fail ("round 0: … differ").
TEST(PhotonMapUpdate, EstimatesFromEditedNeighbourListsEqualAFullEstimate) {
    Fixture f;
    for (const EstimateCase& e : kCases) {
        SCOPED_TRACE(e.name());
        const DiscRegions covered = f.regionsFor(e.radius);
        const DiscRegions* regions = e.regions ? &covered : nullptr;
        ChangingPhotons photons(f.full, f.scene, 151);
        PhotonMap map(photons.liveCache(), f.scene, &f.bvh);
        map.keepLists(true);
        std::vector<Vec3f> current = map.irradiance(f.scene, regions, e.radius, e.k, f.all);
        size_t estimated = 0, queried = 0, changed = 0;
        for (size_t round = 0; round < 6; ++round) {
            const ChangingPhotons::Change change = photons.next(round);
            std::vector<uint32_t> vertices = map.editLists(f.scene, regions, change.removed, false, e.k);
            map.update(change.removed, change.added, f.scene);
            const std::vector<uint32_t> entered = map.editLists(f.scene, regions, change.added, true, e.k);
            ASSERT_TRUE(std::is_sorted(vertices.begin(), vertices.end()));
            ASSERT_TRUE(std::is_sorted(entered.begin(), entered.end()));
            vertices.insert(vertices.end(), entered.begin(), entered.end());
            std::sort(vertices.begin(), vertices.end());
            vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
            const std::vector<Vec3f> before = current;
            map.irradianceAt(f.scene, regions, e.radius, e.k, vertices, current);
            const auto expected = PhotonMap(photons.liveCache(), f.scene, &f.bvh).irradiance(f.scene, regions, e.radius, e.k, f.all);
            EXPECT_TRUE(sameBits(current, expected)) << "round " << round << ": " << differing(current, expected) << " differ";
            estimated += vertices.size();
            queried += map.lastQueries();
            changed += differing(before, expected);
        }
        // The test means something: estimates changed, and the lists answered most of them.
        EXPECT_GT(changed, 0u);
        EXPECT_LT(queried, estimated / 2);
    }
}

// Removing every impact near a vertex drains its list below k (k = 4 here, the bound far short
// of the radius): the bound no longer reaches the k-th, and the vertex must be queried again
// (skipping that check makes this fail).
TEST(PhotonMapUpdate, AListDrainedBelowKIsQueriedAgain) {
    Fixture f;
    const DiscRegions covered = f.regionsFor(0.15f);
    // A floor vertex in the open: the vertex nearest (0.5, 0, 0.5).
    uint32_t centre = 0;
    for (uint32_t v = 0; v < f.scene.vertexCount(); ++v)
        if (length(f.scene.positions[v] - Vec3f(0.5f, 0.0f, 0.5f)) < length(f.scene.positions[centre] - Vec3f(0.5f, 0.0f, 0.5f)))
            centre = v;
    PhotonMap map(f.full, f.scene, &f.bvh);
    map.keepLists(true);
    std::vector<Vec3f> current = map.irradiance(f.scene, &covered, 0.15f, 4, f.all);
    std::vector<Segment> removed, kept;
    f.full.forEachSegment([&](const Segment& s) {
        (s.hasImpact() && length(s.impactPoint() - f.scene.positions[centre]) < 0.12f ? removed : kept).push_back(s);
    });
    const RayCache rest = RayCache::ofSegments(std::move(kept), f.full.maxPhotonPower);
    ASSERT_GT(removed.size(), 8u);  // twice k: more than the list's bound held
    std::vector<uint32_t> vertices = map.editLists(f.scene, &covered, removed, false, 4);
    map.update(removed, {}, f.scene);
    ASSERT_TRUE(std::binary_search(vertices.begin(), vertices.end(), centre));
    map.irradianceAt(f.scene, &covered, 0.15f, 4, vertices, current);
    EXPECT_GT(map.lastQueries(), 0u);
    EXPECT_TRUE(sameBits(current, PhotonMap(rest, f.scene, &f.bvh).irradiance(f.scene, &covered, 0.15f, 4, f.all)));
}

// A vertex whose filter changed (it moved, or its regions did) is forgotten and queried afresh.
TEST(PhotonMapUpdate, AForgottenListIsQueriedAgain) {
    Fixture f;
    const DiscRegions covered = f.regionsFor(0.15f);
    PhotonMap map(f.full, f.scene, &f.bvh);
    map.keepLists(true);
    std::vector<Vec3f> current = map.irradiance(f.scene, &covered, 0.15f, 50, f.all);
    map.irradianceAt(f.scene, &covered, 0.15f, 50, {0, 1, 2}, current);
    EXPECT_EQ(map.lastQueries(), 0u);
    map.forget({1});
    map.irradianceAt(f.scene, &covered, 0.15f, 50, {0, 1, 2}, current);
    EXPECT_EQ(map.lastQueries(), 1u);
}

// update() takes the triangles' front normals of the pose it is given (a turned triangle changes
// which impacts count); here the cube's front sides are turned inside out.
TEST(PhotonMapUpdate, UpdateTakesTheFrontNormalsOfTheNewPose) {
    Fixture f;
    Scene turned = f.scene;
    float floorY = turned.positions[0].y;
    for (const Vec3f& p : turned.positions) floorY = std::min(floorY, p.y);
    for (size_t v = 0; v < turned.vertexCount(); ++v)
        if (turned.positions[v].y > floorY) turned.normals[v] = -turned.normals[v];
    const DiscRegions covered = f.regionsFor(0.15f);
    PhotonMap map(f.full, f.scene, &f.bvh);
    const auto before = map.irradiance(f.scene, &covered, 0.15f, 50, f.all);
    map.update({}, {}, turned);
    const auto after = map.irradiance(f.scene, &covered, 0.15f, 50, f.all);
    EXPECT_TRUE(sameBits(after, PhotonMap(f.full, turned, &f.bvh).irradiance(f.scene, &covered, 0.15f, 50, f.all)));
    EXPECT_FALSE(sameBits(after, before));
}

// Changes that do not match the map are caller errors, reported rather than ignored.
TEST(PhotonMapUpdate, RejectsRemovingAnAbsentImpactAndAddingAPresentOne) {
    Fixture f;
    PhotonMap map(f.full, f.scene, &f.bvh);
    const std::vector<Segment> segments = f.full.decodeAll();
    const Segment& present = *std::find_if(segments.begin(), segments.end(), [](const Segment& s) { return s.hasImpact(); });
    EXPECT_THROW(map.update({}, {present}, f.scene), std::logic_error);
    Segment absent = present;
    absent.path = 1u << 30;
    EXPECT_THROW(map.update({absent}, {}, f.scene), std::logic_error);
}
