// The incremental update (docs/design.md §6): every frame equals a from-scratch computation of that frame,
// bit for bit, for every estimator and DETP rule, with 1 and 2 threads, with and without the
// envelope; nothing drifts over 10,000 frames; a frame where nothing moves changes nothing; and
// hits do not depend on the BVH (the tie rule).
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>

#include "pipeline/frame_solver.h"
#include "scene/animation.h"
#include "estimate/final_gather.h"
#include "scene/back_sides.h"
#include "estimate/direct_light.h"
#include "test_support.h"

using namespace qsgi;

namespace {

// A solve's radiosity, its record kept in `record` for the checks that read it.
const VertexRadiosity& recorded(FrameTiming& record, FrameSolver::Solution solved) {
    record = std::move(solved.record);
    return solved.radiosity;
}


// A scene, the node that moves, and where it is at each frame.
struct AnimatedScene {
    std::string name;
    std::function<Scene()> make;
    std::string moverNode;
    std::function<Vec3d(int)> offset;  // the mover's translation at a frame
    int frames;
    std::function<Vec3d(int)> scale = [](int) { return Vec3d(1.0); };  // and its scale (0: hidden)
    std::function<std::array<double, 4>(int)> rotation = [](int) { return std::array<double, 4>{0, 0, 0, 1}; };  // x, y, z, w

    std::vector<Transform> localsAt(const Scene& scene, int mover, int frame) const {
        std::vector<Transform> locals = scene.restLocals();
        locals[mover] = Transform::fromTRS(offset(frame), rotation(frame), scale(frame)) * locals[mover];
        return locals;
    }
};

int nodeNamed(const Scene& scene, const std::string& name) {
    for (size_t i = 0; i < scene.nodes.size(); ++i)
        if (scene.nodes[i].name == name) return int(i);
    return -1;
}

// Marks the mover dynamic and sweeps the animation's bounds, as RenderJob does for a file.
Scene prepare(const AnimatedScene& a, int& mover) {
    Scene scene = a.make();
    mover = nodeNamed(scene, a.moverNode);
    scene.markDynamic({mover});
    sweepAnimationBounds(scene, a.frames - 1, [&](int f) { return a.localsAt(scene, mover, f); });
    return scene;
}

bool sameBits(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3f)) == 0;
}

size_t firstDifference(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i)
        if (std::memcmp(&a[i], &b[i], sizeof(Vec3f)) != 0) return i;
    return a.size();
}

struct EstimatorCase {
    std::string name;
    EstimatorKind kind;
    DetpBoundary rule;
    bool index = true;
};

const EstimatorCase kEstimators[] = {
    {"impact-count", EstimatorKind::ImpactCount, DetpBoundary::Clip},
    {"photon-map clip", EstimatorKind::PhotonMap, DetpBoundary::Clip},
    {"photon-map paper", EstimatorKind::PhotonMap, DetpBoundary::Paper},
    {"detp clip", EstimatorKind::Detp, DetpBoundary::Clip},
    {"detp linear", EstimatorKind::Detp, DetpBoundary::Linear},
    {"detp paper", EstimatorKind::Detp, DetpBoundary::Paper},
    {"detp clip brute force", EstimatorKind::Detp, DetpBoundary::Clip, false},
};

FrameSolverSettings solverSettings(const EstimatorCase& e, float radius, uint64_t photons) {
    FrameSolverSettings s;
    s.estimator.kind = e.kind;
    s.estimator.detp.boundary = e.rule;
    s.estimator.radius = radius;
    s.estimator.photonMap.k = 20;
    s.estimator.useIndex = e.index;
    s.trace.photons = photons;
    s.trace.seed = 7;
    s.update.alwaysUpdate = true;  // these tests exercise the update, however large the change
    return s;
}

// Runs the animation incrementally and checks every frame against a from-scratch solve.
void expectIncrementalEqualsFull(const AnimatedScene& a, const EstimatorCase& e, int threads, bool envelope,
                                 uint64_t photons, float radius, uint32_t generations = TrackedPaths::kGenerations,
                                 const LightingSettings& lighting = {}) {
    SCOPED_TRACE(a.name + " / " + e.name + " / threads " + std::to_string(threads) + (envelope ? "" : " / no envelope"));
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    int moverA = -1, moverB = -1;
    Scene incScene = prepare(a, moverA), fullScene = prepare(a, moverB);
    EmbreeDevice device;
    FrameSolverSettings incremental = solverSettings(e, radius, photons);
    incremental.update.useEnvelope = envelope;
    incremental.update.trackedGenerations = generations;
    incremental.lighting = lighting;
    FrameSolverSettings full = incremental;
    full.update.fullRecompute = true;
    FrameSolver inc(incScene, device, incremental), ref(fullScene, device, full);
    uint64_t retraced = 0, gatherRecast = 0, gatherFull = 0;
    for (int f = 0; f < a.frames; ++f) {
        FrameTiming wi, wf;
        const VertexRadiosity& ri = recorded(wi, inc.solve(a.localsAt(incScene, moverA, f)));
        const VertexRadiosity& rf = recorded(wf, ref.solve(a.localsAt(fullScene, moverB, f)));
        if (f > 0) {
            EXPECT_FALSE(wi.fromScratch);
            retraced += wi.pathsRetraced;
            gatherRecast += wi.gatherRays;
            gatherFull += wf.gatherRays;
        }
        ASSERT_TRUE(sameBits(ri.radiosity, rf.radiosity))
            << "frame " << f << ": first differing vertex " << firstDifference(ri.radiosity, rf.radiosity);
        ASSERT_TRUE(sameBits(ri.irradiance, rf.irradiance)) << "frame " << f;
    }
    // The scenes are built so the mover is in the light: the update did real work.
    EXPECT_GT(retraced, 0u);
    // The gather re-cast some rays each frame, and fewer than a full recomputation casts.
    if (lighting.gathers()) {
        EXPECT_GT(gatherRecast, 0u);
        EXPECT_LT(gatherRecast, gatherFull);
        // A full recomputation keeps no hits: it casts each vertex's first rays once more to tell
        // covered vertices (FinalGather::castCovered). (With the cache it keeps its records' hits:
        // the probes and the records' rays, which depend on the records placed.)
        if (!lighting.cachesGather()) {
            EXPECT_EQ(gatherFull, uint64_t(a.frames - 1) * incScene.vertexCount() *
                                      (lighting.gatherRays + std::min(lighting.gatherRays, FinalGather::kCoverRays)));
        }
    }
    // A lowered generation limit is there to make the renumbering run.
    if (generations < TrackedPaths::kGenerations) {
        ASSERT_NE(inc.trackedPaths(), nullptr);
        EXPECT_GT(inc.trackedPaths()->renumberings(), 0u);
    }
}

Vec3d slide(int f, double dx, double dz) { return Vec3d(dx * f, 0, dz * f); }

// The scenes of the issue: the mover casts a shadow on lit static surfaces and is lit itself
// (cube on a floor under a light); it stands on the floor, within r of it (reachable areas
// change); a directional light; a point light far outside the scene; and a mover that leaves
// the static scene's bounds.
std::vector<AnimatedScene> scenes() {
    auto cubeOnFloor = [](bool directional) {
        return [directional] {
            Scene s = testscenes::boxOnFloor(16, 3, Vec3f(0.7f));
            if (directional) {
                PunctualLight l;
                l.type = LightType::Directional;
                l.direction = normalize(Vec3f(0.3f, -1.0f, 0.2f));
                l.intensity = Vec3f(3.0f);
                s.lights.push_back(l);
            } else {
                testscenes::addPointLight(s, Vec3f(0.4f, 2.0f, 0.3f), Vec3f(20.0f));
            }
            return s;
        };
    };
    // Emission is aimed (issue 12) in every scene: the point light above the floor is inside the
    // scene's sphere, yet half its directions reach nothing; this one is far outside it.
    auto farLight = [] {
        Scene s = testscenes::boxOnFloor(16, 3, Vec3f(0.7f));
        testscenes::addPointLight(s, Vec3f(6.0f, 9.0f, 4.0f), Vec3f(400.0f));
        return s;
    };
    return {
        {"shadow and lit mover", cubeOnFloor(false), "Cube", [](int f) { return slide(f, 0.11, 0.05); }, 5},
        {"directional light", cubeOnFloor(true), "Cube", [](int f) { return slide(f, -0.09, 0.07); }, 4},
        {"mover leaves the static bounds", cubeOnFloor(false), "Cube", [](int f) { return slide(f, 0.9, 0.0); }, 4},
        {"light far outside the scene (aimed emission)", farLight, "Cube", [](int f) { return slide(f, 0.1, -0.08); }, 4},
        {"mover lifts off and back", cubeOnFloor(false), "Cube",
         [](int f) { return Vec3d(0.0, f % 2 ? 0.02 : 0.0, 0.03 * f); }, 5},
        // glTF's visibility (docs/design.md §3): hidden by a zero scale, on every axis and on one, then
        // shown again elsewhere.
        {"mover hidden and shown again", cubeOnFloor(false), "Cube", [](int f) { return slide(f, 0.05, 0.0); }, 5,
         [](int f) { return f == 1 ? Vec3d(0.0) : f == 2 ? Vec3d(1, 0, 1) : Vec3d(1.0); }},
    };
}

}  // namespace

TEST(Incremental, EveryFrameEqualsFullRecomputationForEveryEstimator) {
    for (const AnimatedScene& a : scenes())
        for (const EstimatorCase& e : kEstimators) {
            const uint64_t photons = e.index ? 6000 : 1500;
            expectIncrementalEqualsFull(a, e, 2, true, photons, 0.12f);
            if (HasFatalFailure()) return;
        }
}

// The second pass (docs/design.md §5.1): exact direct light and a final gather over the photon
// solution are kept across frames — shadow and gather rays re-cast only where a mover's old or new
// bounds meet them — and every frame still equals a full recomputation, for every estimator, also
// with direct light alone (the estimators then count light after its first bounce only). Lights
// are static (emissive movers are refused: docs/design.md §2), so the emitters never move.
LightingSettings exactDirect(uint32_t gatherRays) {
    LightingSettings l;
    l.direct = DirectLighting::Exact;
    l.directSamples = 4;
    l.gatherRays = gatherRays;
    return l;
}

TEST(Incremental, WithExactDirectAndGatherEveryFrameEqualsFull) {
    const std::vector<AnimatedScene> all = scenes();
    for (const AnimatedScene& a : all)
        for (const EstimatorCase& e : kEstimators) {
            // Every estimator on the first scene; on the others one of each kind (the second
            // pass's update is the same code whatever the estimator under it).
            if (a.name != all[0].name && (!e.index || e.rule != DetpBoundary::Clip)) continue;
            const uint64_t photons = e.index ? 6000 : 1500;
            expectIncrementalEqualsFull(a, e, 2, true, photons, 0.12f, TrackedPaths::kGenerations, exactDirect(16));
            if (HasFatalFailure()) return;
        }
}

// Overlapping parts (issue 56): a sheet sliding 0.5 mm over a plate, its front toward the plate, so
// the plate's vertices it covers change every frame (by the covered-vertex rule's front-face
// branch) and their rays start under it. Every estimator kind, with exact direct light and a gather.
TEST(Incremental, ASheetSlidingAHairOverAPlateEqualsFull) {
    const AnimatedScene a{"sheet sliding a hair over a plate",
                          [] {
                              Scene s = testscenes::plateUnderSheet(0.6f, 16, 0.2f, 6, 0.0005f, false, Vec3f(0.7f));
                              testscenes::addPointLight(s, Vec3f(0.1f, 1.5f, 0.2f), Vec3f(20.0f));
                              return s;
                          },
                          "Sheet", [](int f) { return slide(f, 0.07, 0.03); }, 4};
    for (const EstimatorCase& e : kEstimators) {
        if (!e.index || e.rule != DetpBoundary::Clip) continue;  // impact count, photon map, DETP
        expectIncrementalEqualsFull(a, e, 2, true, 6000, 0.12f, TrackedPaths::kGenerations, exactDirect(16));
        if (HasFatalFailure()) return;
    }
}

// Surfaces as an asset gives them (issue 57): the cube a mover with a textured albedo, vertex
// colours, an alpha-MASK checker cut out of it (so photons, shadow and gather rays pass through
// its holes), a transmission of 0.3 (they pass its panes too) and doubleSided (its inside, which
// light reaches through the holes, is lit as its back sides), the floor textured red and blue
// by halves; the hits' albedo is looked up per texel
// on both, in the first trace, in every retrace and in the decoded records alike. Every estimator
// kind, with the paper's method and with exact direct light and a gather.
TEST(Incremental, ATexturedCutOutMoverEqualsFull) {
    const AnimatedScene a{"textured, cut-out, coloured mover",
                          [] {
                              Scene s = testscenes::boxOnFloor(16, 3, Vec3f(0.7f));
                              testscenes::addPointLight(s, Vec3f(0.4f, 2.0f, 0.3f), Vec3f(20.0f));
                              // The floor: red on x < 0, blue on x > 0 (a 2 x 1 texture over its 4 m).
                              Material floor;
                              floor.albedo = Vec3f(0.9f);
                              const uint32_t floorMaterial = testscenes::addTexturedMaterial(
                                  s, floor, 2, 1, {200, 40, 40, 255, 40, 60, 200, 255});
                              testscenes::paintInstance(s, 0, floorMaterial, 0, 2, Vec3f(-2, 0, -2), 4.0f);
                              // The cube: a 4 x 4 checker, its dark cells cut out (alpha 0).
                              Material cube;
                              cube.alphaMode = AlphaMode::Mask;
                              cube.transmission = 0.3f;  // and a pane: photons, shadow and gather rays pass its share
                              cube.doubleSided = true;   // and two-sided: its inside, seen through the cut-outs, is lit
                              std::vector<uint8_t> checker;
                              for (int y = 0; y < 4; ++y)
                                  for (int x = 0; x < 4; ++x) {
                                      const bool on = (x + y) % 2 == 0;
                                      checker.insert(checker.end(), {uint8_t(on ? 230 : 90), uint8_t(on ? 180 : 90),
                                                                     uint8_t(on ? 60 : 90), uint8_t(on ? 255 : 0)});
                                  }
                              const uint32_t cubeMaterial = testscenes::addTexturedMaterial(s, cube, 4, 4, checker);
                              for (size_t i = 1; i < s.instances.size(); ++i) {  // the cube's five faces
                                  const Vec3f n = s.geometricNormal(s.instances[i].firstTriangle);
                                  const int across = std::fabs(n.x) > 0.5f ? 2 : 0, up = std::fabs(n.y) > 0.5f ? 2 : 1;
                                  testscenes::paintInstance(s, i, cubeMaterial, across, up, Vec3f(-0.3f, 0, -0.3f), 0.6f);
                              }
                              s.vertexColours.assign(s.vertexCount(), Rgba{1, 1, 1, 1});
                              for (uint32_t v = s.instances[1].firstVertex; v < s.vertexCount(); ++v)
                                  s.vertexColours[v] = {0.5f + 0.5f * float(v % 2), 1.0f, 0.8f, 1.0f};
                              addBackSides(s);
                              return s;
                          },
                          "Cube", [](int f) { return slide(f, 0.11, 0.05); }, 4};
    for (const EstimatorCase& e : kEstimators) {
        if (!e.index || e.rule != DetpBoundary::Clip) continue;  // impact count, photon map, DETP
        expectIncrementalEqualsFull(a, e, 2, true, 6000, 0.12f);
        expectIncrementalEqualsFull(a, e, 2, true, 6000, 0.12f, TrackedPaths::kGenerations, exactDirect(16));
        if (HasFatalFailure()) return;
    }
}

// The back sides of a doubleSided tube (lib/scene/back_sides.h) are dark inside, where their cover
// rays meet its back faces, and cast those rays alone; the cube slides into the tube, so that
// its faces meet those rays and the back sides there turn lit, and each later frame must find the
// same dark ones, rays and light as a full recomputation. Every estimator with exact direct light
// and a gather, and with the gather cache.
TEST(Incremental, ACubeSlidingIntoADoubleSidedTubeEqualsFull) {
    const AnimatedScene a{"cube into a doubleSided tube",
                          [] {
                              Scene s = testscenes::cubeBesideTube(Vec3f(0.7f));
                              testscenes::addPointLight(s, Vec3f(0.4f, 2.0f, 0.3f), Vec3f(20.0f));
                              addBackSides(s);
                              return s;
                          },
                          "Cube", [](int f) { return slide(f, 0.3, 0.0); }, 4};
    LightingSettings cached = exactDirect(64);  // 16 probes a vertex, the rest at its records
    cached.gatherCache = 0.1f;
    for (const EstimatorCase& e : kEstimators) {
        if (!e.index || e.rule != DetpBoundary::Clip) continue;
        // 64 rays: a dark back side casts its 16 cover rays and leaves the other 48.
        expectIncrementalEqualsFull(a, e, 2, true, 6000, 0.12f, TrackedPaths::kGenerations, exactDirect(64));
        expectIncrementalEqualsFull(a, e, 2, true, 6000, 0.12f, TrackedPaths::kGenerations, cached);
        if (HasFatalFailure()) return;
    }
}

// Many lights (issue 58): a block sliding among three under 30 lamps and 40 point and spot lights,
// direct light at S = 4, so that the lights join the lamps in the light tree; a later frame
// recasts only the shadow rays the block's old or new bounds meet, and equals a full
// recomputation to the bit. One estimator of each kind, with a gather.
TEST(Incremental, AMoverAmongManyLightsEqualsFull) {
    const AnimatedScene a{"a block among many lights", [] { return testscenes::lampsOverBlocks(12, 30, 40, 3); }, "Block1",
                          [](int f) { return slide(f, 0.15, 0.1); }, 4};
    ASSERT_TRUE(DirectLight::samplesLights(40, exactDirect(16).directSamples));
    for (const EstimatorCase& e : kEstimators) {
        if (!e.index || e.rule != DetpBoundary::Clip) continue;
        expectIncrementalEqualsFull(a, e, 2, true, 6000, 0.12f, TrackedPaths::kGenerations, exactDirect(16));
        if (HasFatalFailure()) return;
    }
}

TEST(Incremental, WithExactDirectEqualsFullWithOneThreadAndWithoutGather) {
    const AnimatedScene a = scenes()[0];
    for (const EstimatorCase& e : kEstimators) {
        if (!e.index) continue;
        expectIncrementalEqualsFull(a, e, 1, true, 6000, 0.12f, TrackedPaths::kGenerations, exactDirect(16));
        expectIncrementalEqualsFull(a, e, 2, true, 6000, 0.12f, TrackedPaths::kGenerations, exactDirect(0));
        if (HasFatalFailure()) return;
    }
}

// Light from the environment (issue 35): its photons come from outside the scene's bounds and its
// shadow rays run to infinity; both are kept and updated as every other light's, to the bit. A sky,
// and a map with a bright low sun the cube's shadow sweeps across, under the paper's method and
// with exact direct light and a gather.
TEST(Incremental, UnderASkyOrAnEnvironmentMapEveryFrameEqualsFull) {
    auto underSky = [](bool map) {
        return [map] {
            Scene s = testscenes::boxOnFloor(16, 3, Vec3f(0.7f));
            if (!map) {
                s.environment = std::make_shared<const EnvironmentLight>(EnvironmentLight::uniform(Vec3f(0.6f, 0.8f, 1.0f)));
                return s;
            }
            std::vector<Vec3f> pixels(16 * 8, Vec3f(0.2f, 0.3f, 0.5f));
            pixels[3 * 16 + 5] = Vec3f(400.0f, 380.0f, 300.0f);  // a sun 20-odd degrees above the horizon
            s.environment = std::make_shared<const EnvironmentLight>(EnvironmentLight::fromPixels(pixels, 16, 8, 35));
            return s;
        };
    };
    const AnimatedScene skies[] = {
        {"under a sky", underSky(false), "Cube", [](int f) { return slide(f, 0.11, 0.05); }, 4},
        {"under an environment map", underSky(true), "Cube", [](int f) { return slide(f, -0.09, 0.07); }, 4},
    };
    for (const AnimatedScene& a : skies)
        for (const EstimatorCase& e : kEstimators) {
            if (!e.index || e.rule != DetpBoundary::Clip) continue;  // impact count, photon map, DETP
            expectIncrementalEqualsFull(a, e, 2, true, 6000, 0.12f);
            expectIncrementalEqualsFull(a, e, 2, true, 6000, 0.12f, TrackedPaths::kGenerations, exactDirect(16));
            if (HasFatalFailure()) return;
        }
}

TEST(Incremental, EqualsFullWithOneThreadAndWithoutTheEnvelope) {
    const AnimatedScene a = scenes()[0];
    for (const EstimatorCase& e : kEstimators) {
        if (!e.index) continue;
        expectIncrementalEqualsFull(a, e, 1, true, 6000, 0.12f);
        expectIncrementalEqualsFull(a, e, 2, false, 6000, 0.12f);
        if (HasFatalFailure()) return;
    }
}

// A tracked path's references carry a 16-bit generation; before one would wrap around, every
// path is renumbered and the grid rebuilt. With room for only 2 retraces per path that happens
// every other frame of a 9-frame animation, and no bit of any frame changes.
TEST(Incremental, RenumberingThePathsChangesNoBits) {
    AnimatedScene a = scenes()[0];
    a.frames = 9;
    for (const EstimatorCase& e : kEstimators) {
        if (!e.index) continue;
        expectIncrementalEqualsFull(a, e, 2, true, 6000, 0.12f, 3);
        if (HasFatalFailure()) return;
    }
}

TEST(Incremental, ThreadCountDoesNotChangeTheBits) {
    const AnimatedScene a = scenes()[0];
    const EstimatorCase e = kEstimators[4];  // detp linear: the most state
    std::vector<std::vector<Vec3f>> results[2];
    for (int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        int mover = -1;
        Scene scene = prepare(a, mover);
        EmbreeDevice device;
        FrameSolver solver(scene, device, solverSettings(e, 0.12f, 6000));
        for (int f = 0; f < a.frames; ++f) {
            FrameTiming w;
            results[threads - 1].push_back(recorded(w, solver.solve(a.localsAt(scene, mover, f))).radiosity);
        }
    }
    for (int f = 0; f < a.frames; ++f) EXPECT_TRUE(sameBits(results[0][size_t(f)], results[1][size_t(f)])) << "frame " << f;
}

// Nothing moves: no path is retraced and no vertex changes. An object moving where no light goes
// (under the floor, lit from above) changes nothing either.
TEST(Incremental, FramesWhereNothingRelevantMovesChangeNothing) {
    for (const EstimatorCase& e : kEstimators) {
        if (!e.index) continue;
        SCOPED_TRACE(e.name);
        AnimatedScene a = scenes()[0];
        a.offset = [](int f) { return f < 2 ? Vec3d(0.0) : Vec3d(0.0, -2.0 - 0.1 * f, 0.0); };
        a.frames = 4;
        int mover = -1;
        Scene scene = prepare(a, mover);
        EmbreeDevice device;
        FrameSolver solver(scene, device, solverSettings(e, 0.12f, 6000));
        std::vector<Vec3f> previous;
        for (int f = 0; f < a.frames; ++f) {
            FrameTiming w;
            const VertexRadiosity& r = recorded(w, solver.solve(a.localsAt(scene, mover, f)));
            if (f == 1) {  // the pose of frame 0 again
                EXPECT_EQ(w.pathsRetraced, 0u);
                EXPECT_EQ(w.verticesUpdated, 0u);
                EXPECT_TRUE(sameBits(r.radiosity, previous));
            }
            if (f == 3) {  // moving in the dark under the floor: only the cube's own vertices change
                EXPECT_EQ(w.pathsRetraced, 0u);
                for (uint32_t v = 0; v < scene.vertexCount(); ++v)
                    if (!scene.vertexDynamic[v]) {
                        ASSERT_EQ(std::memcmp(&r.radiosity[v], &previous[v], sizeof(Vec3f)), 0) << v;
                    }
            }
            previous = r.radiosity;
        }
    }
}

// A zero scale hides a node for its frame (glTF's visibility, docs/design.md §3): its vertices carry
// radiosity 0 and keep their last normals, and it casts no shadow — the floor its shadow covered
// is lit as a bare plane is, E = I h / d³, with no indirect light. The incremental frames equal
// full recomputation on this animation with the other scenes (EveryFrameEqualsFullRecomputation…).
TEST(Visibility, AZeroScaleHidesTheNodeForItsFrame) {
    const AnimatedScene a = scenes().back();
    ASSERT_EQ(a.name, "mover hidden and shown again");
    int mover = -1;
    Scene scene = prepare(a, mover);
    EmbreeDevice device;
    FrameSolver solver(scene, device, solverSettings(kEstimators[0], 0.12f, 200000));
    const Vec3d light(scene.lights[0].position), origin = scene.worldOrigin;
    const double albedo = 0.7, intensity = 20.0;
    auto bareFloor = [&](uint32_t v) {  // radiosity of a lone floor's vertex under the light
        const Vec3d d = light - Vec3d(scene.positions[v]);
        return albedo * intensity * d.y / std::pow(length(d), 3.0);
    };
    std::vector<uint32_t> shadowed;  // static vertices in the cube's shadow at frame 0
    std::vector<Vec3f> visibleNormals;
    for (int f = 0; f < 4; ++f) {
        SCOPED_TRACE("frame " + std::to_string(f));
        FrameTiming w;
        const VertexRadiosity& r = recorded(w, solver.solve(a.localsAt(scene, mover, f)));
        const bool hidden = f == 1 || f == 2;
        double dynamicMax = 0;
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
            ASSERT_TRUE(isFinite(r.radiosity[v]) && isFinite(scene.normals[v])) << v;
            EXPECT_EQ(bool(scene.vertexHidden[v]), hidden && scene.vertexDynamic[v]) << v;
            if (scene.vertexDynamic[v]) {
                dynamicMax = std::max(dynamicMax, double(maxComponent(r.radiosity[v])));
                if (hidden) {
                    EXPECT_EQ(std::memcmp(&scene.normals[v], &visibleNormals[v], sizeof(Vec3f)), 0) << v;
                }
            } else if (f == 0 && Vec3d(scene.positions[v]).y + origin.y < 1e-6 &&
                       double(r.radiosity[v].x) < 0.25 * bareFloor(v)) {
                shadowed.push_back(v);
            }
        }
        if (f == 0) visibleNormals = scene.normals;
        if (hidden) {
            EXPECT_EQ(dynamicMax, 0.0);
            ASSERT_GE(shadowed.size(), 4u);
            double ratio = 0;
            for (uint32_t v : shadowed) ratio += double(r.radiosity[v].x) / bareFloor(v);
            // Measured 0.990 (the 4 vertices within ±0.2 %: about 10⁴ photons each side of the
            // light): the impact count's average over a vertex's triangles runs about 1 % low on
            // a 1/d³ falloff. 5 % leaves room for that and for the noise, far from the < 25 % of
            // the shadow the hidden cube no longer casts.
            EXPECT_NEAR(ratio / double(shadowed.size()), 1.0, 0.05);
        } else {
            EXPECT_GT(dynamicMax, 0.0);
        }
    }
}

// 10,000 frames of a small object moving back and forth: the last frame equals a fresh
// computation of that pose (integer sums leave no drift).
TEST(Incremental, NoDriftOverTenThousandFrames) {
    AnimatedScene a{"drift", [] {
                        Scene s = testscenes::boxOnFloor(6, 1, Vec3f(0.7f));
                        testscenes::addPointLight(s, Vec3f(0.3f, 1.5f, 0.2f), Vec3f(10.0f));
                        return s;
                    },
                    "Cube", [](int f) { return Vec3d(0.25 * std::sin(0.37 * f), 0.0, 0.2 * std::sin(0.23 * f)); }, 10000};
    for (const EstimatorCase& e : {kEstimators[0], kEstimators[4]}) {
        SCOPED_TRACE(e.name);
        int mover = -1;
        Scene scene = prepare(a, mover);
        EmbreeDevice device;
        FrameSolver solver(scene, device, solverSettings(e, 0.15f, 400));
        FrameTiming w;
        for (int f = 0; f < a.frames; ++f) recorded(w, solver.solve(a.localsAt(scene, mover, f)));
        const std::vector<Vec3f> last = recorded(w, solver.solve(a.localsAt(scene, mover, a.frames - 1))).radiosity;
        int freshMover = -1;
        Scene fresh = prepare(a, freshMover);
        FrameSolverSettings s = solverSettings(e, 0.15f, 400);
        s.update.fullRecompute = true;
        FrameSolver reference(fresh, device, s);
        EXPECT_TRUE(sameBits(last, recorded(w, reference.solve(a.localsAt(fresh, freshMover, a.frames - 1))).radiosity));
    }
}

// DETP's update subtracts a removed segment by the crossings remembered when it entered. After
// 1,000 frames of a cube moving back and forth (every frame retracing the paths it meets, most
// of them crossing static discs that remember them) every vertex's answer equals a fresh
// computation of that pose to the bit, for `clip` and `linear` (which remembers moments too),
// and the update really went through remembered crossings.
TEST(Incremental, RememberedCrossingsLeaveNoTraceAfterAThousandFrames) {
    AnimatedScene a{"back and forth", [] {
                        Scene s = testscenes::boxOnFloor(12, 2, Vec3f(0.7f));
                        testscenes::addPointLight(s, Vec3f(0.3f, 1.5f, 0.2f), Vec3f(10.0f));
                        return s;
                    },
                    "Cube", [](int f) { return Vec3d(0.3 * std::sin(0.29 * f), 0.0, 0.25 * std::sin(0.17 * f)); }, 1000};
    for (const EstimatorCase& e : {kEstimators[3], kEstimators[4]}) {
        SCOPED_TRACE(e.name);
        int mover = -1;
        Scene scene = prepare(a, mover);
        EmbreeDevice device;
        FrameSolver solver(scene, device, solverSettings(e, 0.12f, 2000));
        uint64_t forgotten = 0;
        std::vector<Vec3f> last;
        for (int f = 0; f < a.frames; ++f) {
            FrameTiming w;
            last = recorded(w, solver.solve(a.localsAt(scene, mover, f))).irradiance;
            forgotten += w.crossingsForgotten;
        }
        EXPECT_GT(forgotten, 1000u);
        int freshMover = -1;
        Scene fresh = prepare(a, freshMover);
        FrameSolverSettings s = solverSettings(e, 0.12f, 2000);
        s.update.fullRecompute = true;
        FrameSolver reference(fresh, device, s);
        FrameTiming w;
        const std::vector<Vec3f> expected = recorded(w, reference.solve(a.localsAt(fresh, freshMover, a.frames - 1))).irradiance;
        EXPECT_TRUE(sameBits(last, expected)) << "first differing vertex " << firstDifference(last, expected);
    }
}

// Runs `a` with the automatic fallback and with --full-recompute side by side for the estimators
// that update (impact count, photon map, DETP clip): every frame has --full-recompute's bytes,
// and check(frame, record) judges the automatic run's record of it.
// lookAhead: frame 0 is given every step of the animation to judge tracking by (FrameSolver::lookAhead),
// as the render job gives it its sampled steps.
void expectAutomaticEqualsFull(const AnimatedScene& a, const std::function<void(int, const FrameTiming&)>& check,
                               bool lookAhead = false) {
    for (const EstimatorCase& e : {kEstimators[0], kEstimators[1], kEstimators[3]}) {
        SCOPED_TRACE(e.name);
        int moverA = -1, moverB = -1;
        Scene incScene = prepare(a, moverA), fullScene = prepare(a, moverB);
        EmbreeDevice device;
        FrameSolverSettings automatic = solverSettings(e, 0.12f, 3000);
        automatic.update.alwaysUpdate = false;
        FrameSolverSettings full = automatic;
        full.update.fullRecompute = true;
        FrameSolver inc(incScene, device, automatic), ref(fullScene, device, full);
        if (lookAhead) {
            std::vector<std::pair<Pose, Pose>> steps;
            for (int f = 1; f < a.frames; ++f) steps.emplace_back(a.localsAt(incScene, moverA, f - 1), a.localsAt(incScene, moverA, f));
            inc.lookAhead(std::move(steps));
        }
        for (int f = 0; f < a.frames; ++f) {
            FrameTiming wi, wf;
            const std::vector<Vec3f> ri = recorded(wi, inc.solve(a.localsAt(incScene, moverA, f))).radiosity;
            const std::vector<Vec3f> rf = recorded(wf, ref.solve(a.localsAt(fullScene, moverB, f))).radiosity;
            EXPECT_TRUE(sameBits(ri, rf)) << "frame " << f << ": first differing vertex " << firstDifference(ri, rf);
            // The scenes themselves too: the normals reach the frame's files, and a hidden vertex
            // keeps the last one a visible pose gave it (the look ahead must leave none behind).
            EXPECT_TRUE(sameBits(incScene.normals, fullScene.normals)) << "frame " << f << ": normals";
            EXPECT_EQ(wf.fromScratchReason, f == 0 ? "" : "full-recompute");
            // A frame that fell back to scratch keeps no update state of the frames before it
            // (DETP's remembered crossings go with the tracked paths): what it holds is what
            // --full-recompute holds. The photon map keeps its neighbour lists whenever updates
            // may follow, so its state is not --full-recompute's.
            if (f > 0 && wi.fromScratch && e.kind != EstimatorKind::PhotonMap) {
                EXPECT_EQ(wi.estimatorStateBytes, wf.estimatorStateBytes) << "frame " << f;
            }
            check(f, wi);
        }
    }
}

// A change so large that updating would cost more than recomputing (the whole floor under the
// light moves, so nearly every path hit a moving triangle) is computed from scratch, with the
// bytes of --full-recompute, and logged as such with the prediction it judged by; when the floor
// then pauses, the next frame is an update again that retraces nothing and predicts nothing.
TEST(Incremental, AChangeTooLargeToUpdateFallsBackToScratchWithTheSameBytes) {
    AnimatedScene a{"moving floor", [] {
                        Scene s = testscenes::boxOnFloor(12, 2, Vec3f(0.7f));
                        testscenes::addPointLight(s, Vec3f(0.3f, 1.5f, 0.2f), Vec3f(10.0f));
                        return s;
                    },
                    "Floor", [](int f) { return Vec3d(0.0, 0.01 * std::min(f, 3), 0.0); }, 6};
    expectAutomaticEqualsFull(a, [](int f, const FrameTiming& wi) {
        if (f >= 1 && f <= 3) {  // the floor moves
            EXPECT_TRUE(wi.fromScratch) << "frame " << f;
            EXPECT_EQ(wi.fromScratchReason, "change-too-large") << "frame " << f;
            EXPECT_GT(wi.predictedUpdateShare, 0.8) << "frame " << f;
        }
        if (f >= 4) {  // it pauses
            EXPECT_FALSE(wi.fromScratch) << "frame " << f;
            EXPECT_EQ(wi.predictedUpdateShare, 0.0) << "frame " << f;
            EXPECT_EQ(wi.pathsRetraced, 0u) << "frame " << f;
            EXPECT_EQ(wi.verticesUpdated, 0u) << "frame " << f;
        }
    });
}

// A plate under the light that nearly every photon meets, sliding across the floor.
AnimatedScene sweepingPanel() {
    return {"sweeping panel",
            [] {
                Scene s = testscenes::plateOverFloor(12, 0.7f, 0.8f, Vec3f(0.7f));
                testscenes::addPointLight(s, Vec3f(0.0f, 1.5f, 0.0f), Vec3f(10.0f));
                return s;
            },
            "Plate", [](int f) { return Vec3d(-0.6 + 0.3 * f, 0.0, 0.0); }, 5};
}

// The sweeping panel (issue 34): a plate under the light that nearly every photon meets slides
// across the floor, so nearly every path changes every frame. The solver sees this from counts,
// before it traces anything again, computes every frame from scratch (never paying for an update
// and a fallback both), and gives --full-recompute's bytes.
TEST(Incremental, APanelSweepingUnderTheLightFallsBackEveryFrameFromCountsAlone) {
    const AnimatedScene a = sweepingPanel();
    expectAutomaticEqualsFull(a, [](int f, const FrameTiming& wi) {
        EXPECT_TRUE(wi.fromScratch) << "frame " << f;
        EXPECT_EQ(wi.fromScratchReason, f == 0 ? "" : "change-too-large") << "frame " << f;
        if (f > 0) {
            EXPECT_GT(wi.predictedUpdateShare, 0.8) << "frame " << f;
        }
        // Decided before any retrace: no path was looked for or traced again.
        EXPECT_EQ(wi.pathsAffectedByImpact + wi.pathsAffectedByBlocking, 0u) << "frame " << f;
        EXPECT_EQ(wi.segmentsRemoved, 0u) << "frame " << f;
    });
}

// Frame 0 decides tracking from the animation it is given (issue 60): the panel sweeping under the
// light changes nearly every path every step, so frame 0, judging the steps from its own photons,
// builds no tracking state (none is ever built), every frame is computed from scratch, and the
// bytes are --full-recompute's.
TEST(Incremental, AMoverCrossingTheSceneIsJudgedAtFrameZeroAndNothingIsTracked) {
    const AnimatedScene a = sweepingPanel();
    expectAutomaticEqualsFull(
        a,
        [](int f, const FrameTiming& wi) {
            EXPECT_TRUE(wi.fromScratch) << "frame " << f;
            EXPECT_EQ(wi.trackedPaths, 0u) << "frame " << f;
            EXPECT_EQ(wi.trackedBytes, 0u) << "frame " << f;
            if (f == 0) {
                EXPECT_GT(wi.predictedUpdateShare, 0.8) << "the steps' median";
            }
        },
        true);
}

// A small mover (the cube sliding by a few centimetres a frame): with the look ahead, every frame
// is solved as without it (from scratch or updated alike), and frame 0 tracks the very paths it
// tracks without it wherever the frames after it update. Where they fall back all the same
// (impact count at 3000 photons here: frame 1 predicts more than 0.8 of a frame), frame 0 now
// foresees it and builds nothing.
TEST(Incremental, ASmallMoverIsJudgedAtFrameZeroAndTracksAsBefore) {
    // The cube on a floor fine enough that its own vertices, recomputed every frame, are a small
    // share of the scene's.
    const AnimatedScene a{"small mover",
                          [] {
                              Scene s = testscenes::boxOnFloor(48, 3, Vec3f(0.7f));
                              testscenes::addPointLight(s, Vec3f(0.4f, 2.0f, 0.3f), Vec3f(20.0f));
                              return s;
                          },
                          "Cube", [](int f) { return slide(f, 0.05, 0.03); }, 4};
    std::vector<FrameTiming> without, with;
    expectAutomaticEqualsFull(a, [&](int, const FrameTiming& wi) { without.push_back(wi); }, false);
    expectAutomaticEqualsFull(a, [&](int, const FrameTiming& wi) { with.push_back(wi); }, true);
    ASSERT_EQ(with.size(), without.size());
    size_t tracked = 0;
    for (size_t i = 0; i < with.size(); i += size_t(a.frames)) {  // each estimator's frames
        const bool laterUpdate = !without[i + 1].fromScratch;
        std::printf("run %zu: frame 1 predicted %.3f of a frame (%s), frame 0 foresaw %.3f\n", i, without[i + 1].predictedUpdateShare, without[i + 1].fromScratchReason.c_str(), with[i].predictedUpdateShare);
        for (int f = 0; f < a.frames; ++f) EXPECT_EQ(with[i + f].fromScratch, without[i + f].fromScratch) << "run " << i << " frame " << f;
        if (laterUpdate) {
            EXPECT_EQ(with[i].trackedPaths, without[i].trackedPaths) << "run " << i;
            EXPECT_LE(with[i].predictedUpdateShare, 0.8) << "run " << i;
            ++tracked;
        } else {
            EXPECT_EQ(with[i].trackedPaths, 0u) << "run " << i;
            EXPECT_GT(with[i].predictedUpdateShare, 0.8) << "run " << i;
        }
    }
    EXPECT_GE(tracked, 2u) << "the estimators that update this mover";
}

// A mover hidden at frame 0 (scale 0, as glTF animates visibility) and shown from frame 1: the look
// ahead poses it visible and back, and its hidden vertices must keep the normals a run without the
// look ahead gives them (expectAutomaticEqualsFull compares the scenes' normals every frame).
TEST(Incremental, TheLookAheadLeavesAMoverHiddenAtFrameZeroAsItFoundIt) {
    AnimatedScene a = scenes()[0];
    a.scale = [](int f) { return Vec3d(f == 0 ? 0.0 : 1.0); };
    // Turned as it appears (30° about y, then more), so that its normals differ from the rest pose's.
    a.rotation = [](int f) {
        const double half = 0.5 * (M_PI / 6) * f;
        return std::array<double, 4>{0, std::sin(half), 0, std::cos(half)};
    };
    expectAutomaticEqualsFull(a, [](int, const FrameTiming&) {}, true);
}

// DETP's FLANN candidates have no update: its frames are computed from scratch, say so, and
// still equal --full-recompute.
TEST(Incremental, AnEstimatorWithoutAnUpdateLogsItsFramesAsFromScratch) {
    const AnimatedScene a = scenes()[0];
    EstimatorCase e = kEstimators[3];
    int moverA = -1, moverB = -1;
    Scene incScene = prepare(a, moverA), fullScene = prepare(a, moverB);
    EmbreeDevice device;
    FrameSolverSettings flann = solverSettings(e, 0.12f, 3000);
    flann.estimator.detp.index = DetpIndex::Flann;
    FrameSolverSettings full = flann;
    full.update.fullRecompute = true;
    FrameSolver inc(incScene, device, flann), ref(fullScene, device, full);
    for (int f = 0; f < 3; ++f) {
        FrameTiming wi, wf;
        const std::vector<Vec3f> ri = recorded(wi, inc.solve(a.localsAt(incScene, moverA, f))).radiosity;
        EXPECT_TRUE(sameBits(ri, recorded(wf, ref.solve(a.localsAt(fullScene, moverB, f))).radiosity)) << "frame " << f;
        EXPECT_TRUE(wi.fromScratch);
        EXPECT_EQ(wi.fromScratchReason, f == 0 ? "" : "estimator");
    }
}

// A first frame keeps the tails it will track while it traces (EnvelopeTails) instead of decoding
// its cache again: the tracked paths made from them are the ones made from the cache — the same
// paths in the same slots, every segment to the bit — with and without a disc's extension past
// the impact. Both kinds of path occur (tracked and folded), so a rule that kept all or none
// would fail.
TEST(TrackedPaths, TailsKeptWhileTracingAreTheCachesOwn) {
    AnimatedScene a{"box", [] {
                        Scene s = testscenes::boxOnFloor(16, 3, Vec3f(0.7f));
                        testscenes::addPointLight(s, Vec3f(0.3f, 1.5f, 0.2f), Vec3f(10.0f));
                        return s;
                    },
                    "Cube", [](int f) { return Vec3d(0.05 * f, 0.0, 0.0); }, 4};
    int mover = -1;
    const Scene scene = prepare(a, mover);
    ASSERT_GE(mover, 0);
    EmbreeDevice device;
    const SceneBvh bvh(device, scene);
    const PhotonTracer tracer(scene, bvh, TraceSettings{20000, 7, 32, EmissionAim{}, PhotonSampling{}});
    for (const float extension : {0.0f, 0.1f}) {
        SCOPED_TRACE("extension " + std::to_string(extension));
        const Envelope envelope = Envelope::ofAnimation(scene, envelopeMargin(extension > 0, extension, scene.sceneEpsilon()));
        const Bounds3f grid = envelope.bounds();
        const float cell = grid.extent() / 8;
        EnvelopeTails tails{envelope, extension, {}};
        const RayCache cache = tracer.traceAll(nullptr, &tails);
        const TrackedPaths fromCache(cache, envelope, extension, grid, cell);
        const TrackedPaths fromTails(tracer.source(), tails, grid, cell);
        ASSERT_GT(fromCache.trackedPaths(), 0u);
        ASSERT_LT(fromCache.trackedSegments(), cache.segmentCount());
        ASSERT_EQ(fromTails.trackedPaths(), fromCache.trackedPaths());
        ASSERT_EQ(fromTails.trackedSegments(), fromCache.trackedSegments());
        EXPECT_EQ(fromTails.bytes(), fromCache.bytes());
        std::vector<Segment> expected, got;
        fromCache.allSegments(expected);
        fromTails.allSegments(got);
        ASSERT_EQ(got.size(), expected.size());
        for (size_t i = 0; i < got.size(); ++i) {
            const Segment &x = got[i], &y = expected[i];
            ASSERT_TRUE(x.origin == y.origin && x.direction == y.direction && x.length == y.length && x.power == y.power &&
                        x.triangle == y.triangle && x.path == y.path && x.bounce == y.bounce && x.impactDynamic == y.impactDynamic)
                << "tracked segment " << i;
        }
    }
}

// Equal distances are ordered by (path, bounce): the k nearest impacts are the same set whatever
// order the cache holds them in (an incremental update reorders it).
TEST(PhotonMapOrder, KNearestDoNotDependOnTheCacheOrder) {
    Scene s = testscenes::boxOnFloor(8, 2, Vec3f(0.6f));
    testscenes::addPointLight(s, Vec3f(0.2f, 1.5f, 0.1f), Vec3f(10.0f));
    const RayCache traced = traceScene(s, 4000, 3);
    std::vector<Segment> segments = traced.decodeAll();
    // Duplicate every impact, so that every distance ties with another.
    const size_t n = segments.size();
    for (size_t i = 0; i < n; ++i) {
        Segment copy = segments[i];
        copy.path += 1000000;
        copy.power = copy.power * 0.5f;  // a different choice among the ties gives a different sum
        segments.push_back(copy);
    }
    const auto cache = [&] { return RayCache::ofSegments(segments, traced.maxPhotonPower); };
    EstimatorSettings settings;
    settings.kind = EstimatorKind::PhotonMap;
    settings.radius = 0.3f;
    settings.photonMap.k = 16;  // 15 summed: one of a tied pair is in, the other out
    const std::vector<Vec3f> forward = estimateWith(s, cache(), settings).irradiance;
    std::reverse(segments.begin(), segments.end());
    EXPECT_TRUE(sameBits(forward, estimateWith(s, cache(), settings).irradiance));
    std::rotate(segments.begin(), segments.begin() + int64_t(n / 3), segments.end());
    settings.useIndex = false;
    EXPECT_TRUE(sameBits(forward, estimateWith(s, cache(), settings).irradiance));
}
