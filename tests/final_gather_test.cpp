// The final gather and the second pass (FinalGather, TwoPassLighting, docs/design.md §5.1): the
// closed sphere's analytic solution through the whole FrameSolver; rays that meet a back face
// return nothing; the answer's bits do not depend on the thread count.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "estimate/disc_regions.h"
#include "estimate/final_gather.h"
#include "estimate/two_pass_lighting.h"
#include "estimate/vertex_starts.h"
#include "pipeline/frame_solver.h"
#include "test_support.h"
#include "util/rounding.h"
#include "trace/scene_bvh.h"

using namespace qsgi;

namespace {

using Rig = SecondPassRig;

double seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

bool sameBits(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3f)) == 0;
}

bool inInstance(const Scene& scene, size_t instance, uint32_t v) {
    const MeshInstance& in = scene.instances[instance];
    return v >= in.firstVertex && v < in.firstVertex + in.vertexCount;
}

bool triangleOfInstance(const Scene& scene, size_t instance, uint32_t t) {
    const MeshInstance& in = scene.instances[instance];
    return t >= in.firstTriangle && t < in.firstTriangle + in.triangleCount;
}

// Configuration factor from a differential element at p facing +y to the horizontal rectangle
// spanned by instance 1's vertices (above p): a differential element parallel to a rectangle, the
// signed sum of four corner rectangles, each 1/(2π) [A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²) atan(A/√(1+B²))].
double sheetFactor(const Scene& scene, const Vec3d& p) {
    const MeshInstance& in = scene.instances[1];
    double x0 = 1e30, x1 = -1e30, z0 = 1e30, z1 = -1e30, y = 0;
    for (uint32_t v = in.firstVertex; v < in.firstVertex + in.vertexCount; ++v) {
        const Vec3f& q = scene.positions[v];
        x0 = std::min(x0, double(q.x)), x1 = std::max(x1, double(q.x));
        z0 = std::min(z0, double(q.z)), z1 = std::max(z1, double(q.z));
        y = q.y;
    }
    const double c = y - p.y;
    auto corner = [c](double a, double b) {
        const double A = a / c, B = b / c, sa = std::sqrt(1 + A * A), sb = std::sqrt(1 + B * B);
        return (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb)) / (2 * M_PI);
    };
    x0 -= p.x, x1 -= p.x, z0 -= p.z, z1 -= p.z;
    return corner(x1, z1) - corner(x0, z1) - corner(x1, z0) + corner(x0, z0);
}

}  // namespace

// Inside a closed sphere (R = 1, ρ = 0.5, I = 1 W/sr at the centre, no emissive triangle) the exact
// answer is E = E_d / (1 − ρ) = 2 W/m² everywhere. Run through the whole FrameSolver: impact count
// (after the first bounce) on 10^6 photons, direct light exact, 256 gather rays.
//
// The tessellation's own error, accounted for: the icosphere's vertices lie on the sphere but its
// flat triangles inside it (area A < 4π); the gather rays leave from each vertex's start s_v, a
// float error off v (issue 56; before it, lifted by ε⁺ ≈ r²/2R = 1.25 mm here), and direct light is
// taken at v itself. So the test's
// exact answer is the second pass's own definition on this mesh:
//   E_v = D_v + ρ (⟨D⟩ + Ī),  D_v = I cosθ / |v|² at the vertex (exact; tests/direct_light_test.cpp),
// ⟨D⟩ the mean of D over the vertices the gather interpolates, Ī the indirect irradiance on the
// mesh: its power balance (all light lands, a share ρ is reflected each bounce) gives an
// area-weighted mean Ī = 4π I ρ / ((1 − ρ) A), and a uniform enclosure irradiates every point of
// it alike. (The gather's cosine-weighted rays from a point on a sphere land uniformly by area, so
// the gather averages F over the area.) Against this, the statistical error: the photons' indirect
// estimate has ≈ 10^6 impacts, ~50 per triangle, so I_u is noisy by ~6 % per vertex; the gather
// averages 256 of them (times ρ), ≈ 0.1 % of E per vertex. The issue asks for 0.5 %: required both
// against the mesh's exact answer and against the ideal 2 W/m², which differs from it by the
// tessellation's bias on D (printed).
TEST(FinalGather, ClosedSphereTwoPassGivesTheAnalyticIrradiance) {
    const auto start = std::chrono::steady_clock::now();
    const double rho = 0.5, I = 1.0, R = 1.0;
    Scene scene = testscenes::closedSphere(float(R), 5, Vec3f(float(rho)));
    testscenes::addPointLight(scene, Vec3f(0.0f), Vec3f(float(I)));
    const EmbreeDevice device;
    FrameSolverSettings s;
    s.estimator.kind = EstimatorKind::ImpactCount;
    s.trace = TraceSettings{1000000, 5, 32, EmissionAim{}, PhotonSampling{}};
    s.lighting.direct = DirectLighting::Exact;
    s.lighting.gatherRays = 256;
    s.update.fullRecompute = true;
    FrameSolver solver(scene, device, s);
    const FrameSolver::Solution solved = solver.solve(scene.restPose());
    const FrameTiming& stats = solved.record;
    const std::vector<Vec3f> E = solved.radiosity.irradiance;
    ASSERT_EQ(E.size(), scene.vertexCount());
    const size_t n = scene.vertexCount();

    double area = 0;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) area += scene.triangleArea(t);
    const double indirect = 4 * M_PI * I * rho / ((1 - rho) * area);
    const Vec3d light(scene.lights[0].position);
    std::vector<double> D(n);
    double meanD = 0;
    for (uint32_t v = 0; v < n; ++v) {
        const Vec3d p(scene.positions[v]);
        const Vec3d d = light - p;
        const double d2 = dot(d, d);
        D[v] = I * dot(Vec3d(scene.normals[v]), d / std::sqrt(d2)) / d2;
        meanD += D[v] / double(n);
    }
    double sum2 = 0, sumIdeal2 = 0, mean = 0;
    for (uint32_t v = 0; v < n; ++v) {
        const double exact = D[v] + rho * (meanD + indirect);
        const double e = double(E[v].y) / exact - 1, eIdeal = double(E[v].y) / (I / (R * R) / (1 - rho)) - 1;
        // Grey light and albedo: the channels are the same numbers.
        ASSERT_EQ(E[v].x, E[v].y) << "vertex " << v;
        sum2 += e * e;
        sumIdeal2 += eIdeal * eIdeal;
        mean += e / double(n);
    }
    const double rms = std::sqrt(sum2 / double(n)), rmsIdeal = std::sqrt(sumIdeal2 / double(n));
    std::printf("sphere: %zu vertices, A/4π = %.5f, <D> = %.5f (tessellation bias %+.3f %%), indirect %.5f; E vs mesh exact: RMS %.3f %%, "
                "mean %+.3f %%; vs 2 W/m²: RMS %.3f %%; %.1f s\n",
                n, area / (4 * M_PI), meanD, 100 * (meanD - 1), indirect, 100 * rms, 100 * mean, 100 * rmsIdeal, seconds(start));
    EXPECT_LT(rms, 0.005);
    EXPECT_LT(rmsIdeal, 0.005);
    // The vertices' mean error is the photons' error on the total indirect power (the gather
    // averages F over the area): ≈ 10^6 impacts of equal power (ρ = survival = 0.5), Poisson
    // relative error ≤ 10^-3 on Ī, ρĪ/E = 1/4 of E, so ≈ 0.025 % (Sobol photons do better); four
    // times that is allowed.
    EXPECT_LT(std::abs(mean), 0.001);
    // M a vertex, and the 16 that tell covered vertices first (this solve keeps no hits to read them from).
    EXPECT_EQ(stats.gatherRays, uint64_t(n) * (256 + FinalGather::kCoverRays));
}

// A plate facing up under a larger single-sided sheet, 0.3 m above it. With the sheet's front
// facing up, the plate sees only its back: every gather ray from the plate misses or meets a back
// face (GatherHit::kBackFace) and returns 0 — vertex radiosity is the front side's. Turned to face
// down (winding and normals), the same rays meet its front.
//
// With F = 1 on the sheet, the gathered value is the share of the vertex's M cosine-weighted rays
// that meet the sheet (interpolating 1 gives 1 up to the 16-bit barycentrics: weights sum to 1
// within 2/65535), whose expectation is the configuration factor F_s of the sheet. The rays
// (v's own points of a (0, 10, 2)-net, scrambled) give a share whose variance is at most
// 2 · F_s (1 − F_s) / M (Owen's bound for scrambled (0, m, 2)-nets in base 2); 5 such standard
// deviations are allowed. Then the whole second pass: a point light above lights the up-facing
// sheet's front; with the photons' answer I = 1 on the sheet, F = ρ (D + I) > 0 there, yet the plate
// (in the sheet's shadow) gets exactly 0. Turned down, the sheet has D = 0 (the light is behind it),
// F = ρ · 1, and the plate gets ρ times the share of its rays that meet the sheet.
TEST(FinalGather, RaysMeetingABackFaceReturnNothing) {
    const auto start = std::chrono::steady_clock::now();
    const float plateHalf = 0.2f, sheetHalf = 0.6f, gap = 0.3f;
    const double rho = 0.5;
    const uint32_t M = 1024;
    Scene up = testscenes::plateUnderSheet(plateHalf, 8, sheetHalf, 12, gap, true, Vec3f(float(rho)));
    Scene down = testscenes::plateUnderSheet(plateHalf, 8, sheetHalf, 12, gap, false, Vec3f(float(rho)));
    for (Scene* scene : {&up, &down}) testscenes::addPointLight(*scene, Vec3f(0, 1, 0), Vec3f(1.0f));
    const Rig upRig(up), downRig(down);
    FinalGather upGather(M, 3), downGather(M, 3);
    upGather.castAll(up, upRig.bvh, upRig.starts);
    downGather.castAll(down, downRig.bvh, downRig.starts);

    auto onSheet = [](const Scene& scene) {
        std::vector<Vec3f> F(scene.vertexCount(), Vec3f(0.0f));
        for (uint32_t v = 0; v < scene.vertexCount(); ++v)
            if (inInstance(scene, 1, v)) F[v] = Vec3f(1.0f);
        return F;
    };
    std::vector<Vec3f> upShare, downShare;
    upGather.gather(up, onSheet(up), upShare);
    downGather.gather(down, onSheet(down), downShare);

    const MeshInstance& plate = up.instances[0];
    ASSERT_EQ(plate.vertexCount, down.instances[0].vertexCount);
    size_t backHits = 0;
    for (uint32_t v = plate.firstVertex; v < plate.firstVertex + plate.vertexCount; ++v) {
        // The plate's starts do not depend on the sheet 0.3 m away (r = 0.05): the same rays.
        ASSERT_EQ(upRig.starts.point(v), downRig.starts.point(v));
        const Vec3d s(downRig.starts.point(v));
        uint32_t hits = 0;
        for (uint32_t j = 0; j < M; ++j) {
            const GatherHit& a = upGather.hit(v, j);
            const GatherHit& b = downGather.hit(v, j);
            ASSERT_TRUE(a.triangle == GatherHit::kMiss || a.triangle == GatherHit::kBackFace) << "vertex " << v << " ray " << j;
            const bool hitsSheet = b.triangle != GatherHit::kMiss;
            ASSERT_EQ(a.triangle == GatherHit::kBackFace, hitsSheet) << "vertex " << v << " ray " << j;
            if (!hitsSheet) {
                ASSERT_TRUE(std::isinf(a.t) && std::isinf(b.t));
                continue;
            }
            ++hits;
            ASSERT_TRUE(triangleOfInstance(down, 1, b.triangle)) << "vertex " << v << " ray " << j;
            ASSERT_NEAR(a.t, b.t, 1e-5 * b.t);
            // The kept hit lies on the sheet, t from the start: each barycentric is rounded by at
            // most 0.5/65535, which moves the point by ≤ 0.5/65535 (|p1 − p0| + |p2 − p0|) ≤ 1.9e-6 m
            // on the 0.1 m cells; t is a float (~3e-8 m here).
            const Triangle& T = down.triangles[b.triangle];
            const double w1 = b.b1 / 65535.0, w2 = b.b2 / 65535.0;
            const Vec3d x = Vec3d(down.positions[T.v[0]]) * (1 - w1 - w2) + Vec3d(down.positions[T.v[1]]) * w1 +
                            Vec3d(down.positions[T.v[2]]) * w2;
            ASSERT_NEAR(length(x - s), double(b.t), 2.5e-6) << "vertex " << v << " ray " << j;
            ASSERT_GT(x.y - s.y, 0.0);
        }
        backHits += hits;
        const double share = double(hits) / M;
        ASSERT_EQ(upShare[v], Vec3f(0.0f)) << "vertex " << v << ": a back face returned light";
        ASSERT_NEAR(double(downShare[v].y), share, 2.0 / 65535 + 1e-6) << "vertex " << v;
        // The configuration factor of the sheet seen from the start point (the closed form of
        // tests/direct_light_test.cpp), from the sheet's own vertices.
        const double Fs = sheetFactor(down, s);
        ASSERT_NEAR(share, Fs, 5 * std::sqrt(2 * Fs * (1 - Fs) / M)) << "vertex " << v;
    }
    EXPECT_GT(backHits, size_t(plate.vertexCount) * M / 2) << "most rays should meet the sheet";

    // The whole second pass, the photons' answer 1 on the sheet.
    LightingSettings lighting;
    lighting.direct = DirectLighting::Exact;
    lighting.gatherRays = M;
    for (Scene* scene : {&up, &down}) {
        const bool facesUp = scene == &up;
        SCOPED_TRACE(facesUp ? "sheet facing up" : "sheet facing down");
        const Rig& rig = facesUp ? upRig : downRig;
        VertexRadiosity photons;
        photons.irradiance = onSheet(*scene);
        VertexRadiosity out;
        TwoPassLighting second(lighting, 3);
        second.solve(*scene, rig.bvh, rig.starts, photons, out);
        const std::vector<Vec3f>& share = facesUp ? upShare : downShare;
        for (uint32_t v = 0; v < scene->vertexCount(); ++v) {
            if (inInstance(*scene, 1, v)) {
                // The sheet: lit from above on its front only; reflects in both cases (F > 0).
                if (facesUp) {
                    ASSERT_GT(out.irradiance[v].y, 0.0f);
                }
                continue;
            }
            if (facesUp) {
                ASSERT_EQ(out.irradiance[v], Vec3f(0.0f)) << "plate vertex " << v;
            } else {
                ASSERT_GT(out.irradiance[v].y, 0.1f) << "plate vertex " << v;
                ASSERT_NEAR(double(out.irradiance[v].y), rho * double(share[v].y), 1e-6) << "plate vertex " << v;
            }
        }
    }
    std::printf("back faces: %.2f s\n", seconds(start));
}

// A floor under an emissive rectangle and a point light, 4225 floor vertices (many parallel
// chunks), with a photons' answer that is a fixed function of position: what the second pass's
// determinism tests run on.
struct SecondPassFloor {
    Scene scene = withPointLight(
        testscenes::floorUnderEmitter(64, {0.1f, 0.5f, -0.05f}, 0.3f, 0.2f, Vec3f(4.0f, 3.0f, 2.0f), Vec3f(0.6f)));
    Rig rig{scene};
    VertexRadiosity photons = photonsOf(scene);

    static Scene withPointLight(Scene s) {
        testscenes::addPointLight(s, Vec3f(-0.5f, 0.8f, 0.4f), Vec3f(1.0f));
        return s;
    }
    static VertexRadiosity photonsOf(const Scene& s) {
        VertexRadiosity out;
        out.irradiance.resize(s.vertexCount());
        for (uint32_t v = 0; v < s.vertexCount(); ++v) {
            const Vec3f& p = s.positions[v];
            out.irradiance[v] = Vec3f(0.3f + 0.1f * p.x * p.x, 0.2f + 0.05f * p.z, 0.1f);
        }
        return out;
    }
};

// The second pass's bits do not depend on the thread count: each vertex's shadow and gather rays
// are its own numbers, summed in ray order in one thread. A floor under an emissive rectangle and a
// point light, 4225 floor vertices (many parallel chunks), with and without the gather; the
// photons' answer is a fixed function of position.
TEST(TwoPassLighting, BitIdenticalWithOneAndTwoThreads) {
    const auto start = std::chrono::steady_clock::now();
    const SecondPassFloor floor;
    const Scene& scene = floor.scene;
    const Rig& rig = floor.rig;
    const VertexRadiosity& photons = floor.photons;
    for (const uint32_t gatherRays : {0u, 64u}) {
        SCOPED_TRACE(gatherRays ? "with the gather" : "direct only");
        LightingSettings lighting;
        lighting.direct = DirectLighting::Exact;
        lighting.directSamples = 16;
        lighting.gatherRays = gatherRays;
        auto run = [&](int threads) {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
            TwoPassLighting second(lighting, 9);
            VertexRadiosity out;
            second.solve(scene, rig.bvh, rig.starts, photons, out);
            return out;
        };
        const VertexRadiosity one = run(1), two = run(2), twoAgain = run(2);
        ASSERT_EQ(one.irradiance.size(), scene.vertexCount());
        EXPECT_TRUE(sameBits(one.irradiance, two.irradiance));
        EXPECT_TRUE(sameBits(one.radiosity, two.radiosity));
        EXPECT_TRUE(sameBits(two.irradiance, twoAgain.irradiance));
        // Not vacuous: light arrives, from the gather too when there is one.
        double sum = 0;
        for (const Vec3f& e : one.irradiance) sum += e.y;
        EXPECT_GT(sum, 0.0);
    }
    std::printf("threads: %.2f s\n", seconds(start));
}

// A solve that keeps nothing for updates (the last frame, --full-recompute) sums each ray's hit as
// it is found instead of keeping M hits a vertex: the same bits as a solve that keeps them, for 1
// and 2 threads, with almost none of the memory. The floor under an emitter and a point light of
// the test above; the photons' answer a fixed function of position.
TEST(TwoPassLighting, ASolveThatKeepsNoHitsGivesTheSameBits) {
    const SecondPassFloor floor;
    const Scene& scene = floor.scene;
    const Rig& rig = floor.rig;
    const VertexRadiosity& photons = floor.photons;
    LightingSettings lighting;
    lighting.direct = DirectLighting::Exact;
    lighting.directSamples = 16;
    lighting.gatherRays = 64;
    struct Run {
        VertexRadiosity out;
        size_t bytes;
        uint64_t rays;
        bool solved;
    };
    auto run = [&](int threads, bool keep) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        TwoPassLighting second(lighting, 9);
        Run r;
        const SecondPassReport report = second.solve(scene, rig.bvh, rig.starts, photons, r.out, nullptr, keep);
        r.bytes = second.stateBytes();
        r.rays = report.gatherRays;
        r.solved = second.solved();
        return r;
    };
    const Run kept = run(2, true);
    for (int threads : {1, 2}) {
        const Run streamed = run(threads, false);
        EXPECT_TRUE(sameBits(kept.out.irradiance, streamed.out.irradiance)) << threads << " threads";
        EXPECT_TRUE(sameBits(kept.out.radiosity, streamed.out.radiosity)) << threads << " threads";
        // The streamed solve keeps no hits, so it casts each vertex's first rays once more to tell
        // covered vertices (FinalGather::castCovered): the kept one reads them from its hits.
        EXPECT_EQ(streamed.rays, kept.rays + uint64_t(scene.vertexCount()) * std::min(lighting.gatherRays, FinalGather::kCoverRays));
        EXPECT_FALSE(streamed.solved) << "nothing kept: the next frame must solve from scratch";
        // What stays is the starts (point, offset, cover height, normal) and the direct light, 44
        // bytes a vertex, not 16 a ray.
        EXPECT_LE(streamed.bytes, scene.vertexCount() * 44 + 4096);
        EXPECT_GE(kept.bytes, streamed.bytes + scene.vertexCount() * lighting.gatherRays * sizeof(GatherHit));
    }
    EXPECT_TRUE(kept.solved);
    double sum = 0;
    for (const Vec3f& e : kept.out.irradiance) sum += e.y;
    EXPECT_GT(sum, 0.0);
}

// The kept hits' 16-bit quantities round as std::lround did, without its call: at every
// half-integer of [0, 65535], the floats just below and above it, and a sweep between.
TEST(FinalGather, RoundingToSixteenBitsMatchesLround) {
    for (int k = 0; k < 65535; ++k) {
        const float half = float(k) + 0.5f;
        for (float x : {half, std::nextafter(half, 0.0f), std::nextafter(half, 65536.0f), float(k), std::nextafter(float(k), 65536.0f)})
            ASSERT_EQ(roundToUint16(x), uint16_t(std::lround(x))) << x;
    }
    for (float x = 0.0f; x < 4.0f; x = std::nextafter(x, 5.0f) + 1e-7f) ASSERT_EQ(roundToUint16(x), uint16_t(std::lround(x))) << x;
    EXPECT_EQ(roundToUint16(1e-30f), 0);
    EXPECT_EQ(roundToUint16(65535.0f), 65535);
}
