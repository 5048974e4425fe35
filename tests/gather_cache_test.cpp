// The gather cache (GatherCache, docs/method.md "The gather cache"): at tolerance 0 the per-vertex
// gather's bits; its interpolation error against the per-vertex gather of the same rays falls as
// the tolerance does; no record is read across a thin partition; every frame of an update equals
// a full recomputation, for every estimator and thread count, on data/cornell, data/walker and
// data/tree; the answer at a surface point agrees with the vertices'; its kept state is bounded by
// the records, not by vertices × M.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "estimate/final_gather.h"
#include "estimate/gather_cache.h"
#include "estimate/two_pass_lighting.h"
#include "pipeline/frame_solver.h"
#include "scene/gltf_loader.h"
#include "test_support.h"

using namespace qsgi;
namespace fs = std::filesystem;

namespace {

bool sameBits(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3f)) == 0;
}

LightingSettings gatherWith(uint32_t rays, float cache) {
    LightingSettings l;
    l.direct = DirectLighting::Exact;
    l.directSamples = 4;
    l.gatherRays = rays;
    l.gatherCache = cache;
    return l;
}

Scene cornell() {
    Warnings w;
    return loadGltfScene((sourceDir() / "data/cornell/cornell.gltf").string(), w);
}

// One frame of `scene` through the FrameSolver (photons, estimator, second pass), as a render's.
struct Frame {
    VertexRadiosity out;
    FrameTiming stats;
};
Frame solveFrame(Scene scene, const LightingSettings& lighting, uint64_t photons = 30000) {
    const EmbreeDevice device;
    FrameSolverSettings s;
    s.estimator.kind = EstimatorKind::ImpactCount;
    s.trace.photons = photons;
    s.trace.seed = 5;
    s.lighting = lighting;
    s.update.fullRecompute = true;
    FrameSolver solver(scene, device, s);
    Frame f;
    FrameSolver::Solution solved = solver.solve(scene.restPose());
    f.out = solved.radiosity;
    f.stats = std::move(solved.record);
    return f;
}

// The first pass as a smooth function of position, so that the gather's values vary over the scene.
std::vector<Vec3f> smoothFirstPass(const Scene& scene) {
    std::vector<Vec3f> F(scene.vertexCount());
    for (size_t v = 0; v < F.size(); ++v) {
        const Vec3f& p = scene.positions[v];
        F[v] = Vec3f(1.0f + 0.5f * p.x, 1.0f + 0.25f * p.y * p.y, 2.0f - 0.3f * p.z);
    }
    return F;
}

// The gather alone (no direct light), with its cache: what TwoPassLighting does for a solve.
struct CachedGather {
    FinalGather rays;
    GatherCache cache;
    std::vector<Vec3f> values;
    CachedGather(const Scene& scene, const SecondPassRig& rig, uint32_t m, float tolerance, const std::vector<Vec3f>& F)
        : rays(m, 3, GatherCache::kProbeRays), cache(tolerance) {
        rays.castAll(scene, rig.bvh, rig.starts);
        cache.select(scene, rig.bvh, rig.starts, rays);
        rays.setRecords(scene, rig.bvh, rig.starts, cache.records());
        rays.gather(scene, F, values);
        cache.interpolate(values);
    }
};

}  // namespace

// Tolerance 0 asks every vertex for a record of its own: every vertex casts all M rays, and the
// sums — probes first, then the rest, in ray order — are the per-vertex gather's, to the bit.
TEST(GatherCache, ToleranceZeroGivesThePerVertexGathersBits) {
    const Scene scene = cornell();
    const Frame off = solveFrame(scene, gatherWith(32, LightingSettings::kGatherCacheOff));
    const Frame zero = solveFrame(scene, gatherWith(32, 0.0f));
    EXPECT_TRUE(sameBits(off.out.irradiance, zero.out.irradiance));
    EXPECT_TRUE(sameBits(off.out.radiosity, zero.out.radiosity));
    EXPECT_EQ(zero.stats.gatherRecords, scene.vertexCount());
    // Without a cache the solve keeps no hits, so it casts each vertex's first rays once more to
    // tell covered vertices (FinalGather::castCovered); the cache reads them from its probes.
    EXPECT_EQ(zero.stats.gatherRays + uint64_t(scene.vertexCount()) * FinalGather::kCoverRays, off.stats.gatherRays);
    EXPECT_EQ(off.stats.gatherRecords, 0u);
    // With no more rays than the probes every vertex gathers in full: no cache, whatever A.
    const Frame fewOff = solveFrame(scene, gatherWith(GatherCache::kProbeRays, LightingSettings::kGatherCacheOff));
    const Frame fewCached = solveFrame(scene, gatherWith(GatherCache::kProbeRays, 0.5f));
    EXPECT_TRUE(sameBits(fewOff.out.irradiance, fewCached.out.irradiance));
    EXPECT_EQ(fewCached.stats.gatherRecords, 0u);
}

// Against the per-vertex gather of the same rays (records cast exactly the rays the per-vertex
// gather casts there, so the difference is the interpolation's), with M = 256 so that the
// reference's own noise stays below most of what is measured: data/cornell under F a smooth
// function of position, its blocks' contacts and the box's corners making the gathered field
// vary. The error falls as the tolerance does, and the records grow.
TEST(GatherCache, InterpolationErrorFallsWithTheToleranceTowardThePerVertexGather) {
    const Scene scene = cornell();
    const SecondPassRig rig(scene);
    const std::vector<Vec3f> F = smoothFirstPass(scene);
    const uint32_t m = kSanitized ? 64 : 256;
    const CachedGather exact(scene, rig, m, 0.0f, F);
    ASSERT_EQ(exact.cache.recordCount(), scene.vertexCount());
    double previousError = 1e30;
    size_t previousRecords = 0;
    std::vector<double> errors;
    for (const float tolerance : {0.8f, 0.4f, 0.2f, 0.1f, 0.05f}) {
        const CachedGather cached(scene, rig, m, tolerance, F);
        double sum2 = 0;
        size_t n = 0;
        for (size_t v = 0; v < scene.vertexCount(); ++v) {
            const double want = exact.values[v].y;
            ASSERT_TRUE(std::isfinite(cached.values[v].x + cached.values[v].y + cached.values[v].z)) << "vertex " << v;
            if (!(want > 0)) continue;
            const double e = cached.values[v].y / want - 1;
            sum2 += e * e;
            ++n;
        }
        const double rms = std::sqrt(sum2 / double(n));
        std::printf("tolerance %.2f: %zu records of %zu vertices, interpolation error %.3f %%\n", tolerance,
                    cached.cache.recordCount(), scene.vertexCount(), 100 * rms);
        EXPECT_GT(cached.cache.recordCount(), previousRecords) << "tolerance " << tolerance;
        // Halving the tolerance halves the records' spacing; the error falls (5 % slack for the
        // rays' noise between neighbouring records, which interpolation does not remove).
        EXPECT_LT(rms, previousError * 1.05) << "tolerance " << tolerance;
        previousError = rms;
        previousRecords = cached.cache.recordCount();
        errors.push_back(rms);
    }
    // Over a sixteen-fold fall of the tolerance, the error falls at least three-fold.
    EXPECT_LT(errors.back(), errors.front() / 3);
}

// The thin partition of the DETP boundary tests: a zero-thickness wall standing on a floor, welded
// to it, the light on its +z side. Every gather ray from the dark side's floor meets the wall's back
// or escapes, so the per-vertex gather is exactly 0 there; at the loosest tolerance the cache must
// still give exactly 0 — a record from the lit side, read across the wall's foot, would not.
TEST(GatherCache, NoRecordIsReadAcrossAThinPartition) {
    Scene scene = testscenes::partition(64, Vec3f(0.6f));
    testscenes::addPointLight(scene, Vec3f(0.0f, 0.5f, 0.5f), Vec3f(1.0f));
    const SecondPassRig rig(scene);
    // F: bright on the lit side and on the wall (z = 0, whose front faces the lit side), so that
    // a leak shows.
    std::vector<Vec3f> F(scene.vertexCount(), Vec3f(0.0f));
    for (size_t v = 0; v < F.size(); ++v)
        if (double(scene.positions[v].z) + scene.worldOrigin.z >= 0) F[v] = Vec3f(1.0f);
    const CachedGather perVertex(scene, rig, 64, 0.0f, F);
    size_t dark = 0, litBeside = 0;
    for (const float tolerance : {1.0f, 0.3f}) {
        const CachedGather cached(scene, rig, 64, tolerance, F);
        ASSERT_LT(cached.cache.recordCount(), scene.vertexCount() / 2) << "the cache must interpolate to be tested";
        dark = litBeside = 0;
        for (size_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3d p = Vec3d(scene.positions[v]) + scene.worldOrigin;
            if (p.y != 0) continue;
            if (p.z < 0) {
                ++dark;
                ASSERT_EQ(perVertex.values[v].y, 0.0f) << "vertex " << v;
                ASSERT_EQ(cached.values[v].y, 0.0f) << "tolerance " << tolerance << ", dark vertex " << v << " at z " << p.z;
            } else if (p.z > 0 && p.z < 0.1f && cached.values[v].y > 0) {
                ++litBeside;
            }
        }
    }
    EXPECT_GT(dark, 1000u);
    EXPECT_GT(litBeside, 100u) << "the lit side beside the wall gathers light";
}

// Each frame of an animation updated from the last equals a full recomputation, with the cache,
// for every estimator, and the thread count changes no byte: data/cornell (a block moves),
// data/walker (a skinned figure walks) and data/tree (a swinging branch). One run updates with two
// threads, the other recomputes every frame with one, so one comparison of their bytes holds both
// properties (as in VertexFit.IncrementalFramesEqualFullRecomputationOnTheDataScenes): a fault in
// either shows unless the two faults changed the same bytes to the same values.
TEST(GatherCache, IncrementalFramesEqualFullRecomputationOnTheDataScenes) {
    const fs::path dir = testScratchDir("gather-cache-incremental");
    struct Case {
        std::string scene, animation;
        std::vector<std::string> estimators;
    };
    const std::string data = (sourceDir() / "data").string();
    std::vector<Case> cases = {
        {data + "/cornell/cornell.gltf", data + "/cornell/animation.json",
         {"impact-count", "photon-map", "detp --detp-boundary clip", "detp --detp-boundary linear", "detp --detp-boundary paper"}},
        {data + "/walker/walker.gltf", "gltf", {"impact-count", "detp"}},
        {data + "/tree/tree.gltf", data + "/tree/animation.json", {"photon-map", "detp"}},
    };
    if (kSanitized)  // the same code for every estimator: one each under the sanitizers
        for (Case& c : cases) c.estimators.resize(1);
    for (const Case& c : cases)
        for (const std::string& estimator : c.estimators) {
            SCOPED_TRACE(c.scene + " / " + estimator);
            const std::string common = c.scene + " --animation " + c.animation + " --frames 0:2 --photons 20000 --quiet --no-exr" +
                                       " --gather 32 --direct-samples 4 --gather-cache 0.4 --estimator " + estimator;
            const fs::path inc = dir / "inc", full = dir / "full";
            for (const fs::path& p : {inc, full}) fs::remove_all(p);
            CommandResult r = runQsgi("render " + common + " --threads 2 --out " + inc.string());
            ASSERT_EQ(r.exitCode, 0) << r.output;
            r = runQsgi("render " + common + " --threads 1 --full-recompute --out " + full.string());
            ASSERT_EQ(r.exitCode, 0) << r.output;
            for (int f = 0; f <= 2; ++f) {
                const std::string name = "frame_000" + std::to_string(f) + ".ply";
                const std::string a = readFileBytes(inc / name);
                ASSERT_GT(a.size(), 1000u) << name;
                EXPECT_EQ(a, readFileBytes(full / name)) << name << ": updated with two threads against recomputed with one";
            }
            // Each run computed its frames as it was asked to.
            const nlohmann::json fullTiming = nlohmann::json::parse(readFileBytes(full / "timing.json"));
            for (int f = 0; f <= 2; ++f) EXPECT_TRUE(fullTiming["frames"][f]["from_scratch"].get<bool>()) << "frame " << f;
            // The cache ran: records were placed, fewer than the vertices.
            const nlohmann::json timing = nlohmann::json::parse(readFileBytes(inc / "timing.json"));
            for (int f = 1; f <= 2; ++f) EXPECT_FALSE(timing["frames"][f]["from_scratch"].get<bool>()) << "frame " << f;
            const uint64_t records = timing["frames"][0]["gather_records"];
            EXPECT_GT(records, 0u);
            EXPECT_LT(records, timing["frames"][0]["vertices_updated"].get<uint64_t>());
        }
}

// The cache's answer anywhere on a surface: at a vertex it is the vertex's value, inside a triangle
// a weighted mean of records its corners read (between their least and greatest values), or where
// none reaches the corners' values interpolated. data/cornell, F a smooth function of position.
TEST(GatherCache, AnswersAtAnySurfacePointAgreeWithTheVertices) {
    const Scene scene = cornell();
    const SecondPassRig rig(scene);
    const CachedGather cached(scene, rig, 32, 0.4f, smoothFirstPass(scene));
    double worstAtVertex = 0;
    size_t inside = 0;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const Triangle& tri = scene.triangles[t];
        const float corners[3][2] = {{0, 0}, {1, 0}, {0, 1}};
        for (int c = 0; c < 3; ++c) {
            const Vec3f at = cached.cache.irradianceAt(scene, t, corners[c][0], corners[c][1], cached.values);
            const Vec3f want = cached.values[tri.v[c]];
            for (int k = 0; k < 3; ++k) {
                const double scale = std::max(std::fabs(double(want[k])), 1e-6);
                worstAtVertex = std::max(worstAtVertex, std::fabs(double(at[k]) - double(want[k])) / scale);
            }
        }
        // The centroid: between the least and greatest value any vertex of the scene's records
        // read by the corners or the corners themselves holds (a weighted mean of them).
        const Vec3f mid = cached.cache.irradianceAt(scene, t, 1.0f / 3, 1.0f / 3, cached.values);
        float lo = 1e30f, hi = -1e30f;
        for (uint32_t v : tri.v) {
            for (uint32_t r : cached.cache.recordsRead(v)) {
                lo = std::min(lo, cached.values[r].y);
                hi = std::max(hi, cached.values[r].y);
            }
            lo = std::min(lo, cached.values[v].y);
            hi = std::max(hi, cached.values[v].y);
        }
        ASSERT_TRUE(std::isfinite(mid.y));
        EXPECT_GE(mid.y, lo * (1 - 1e-5f) - 1e-6f) << "triangle " << t;
        EXPECT_LE(mid.y, hi * (1 + 1e-5f) + 1e-6f) << "triangle " << t;
        ++inside;
    }
    std::printf("surface points: %zu triangles, worst relative difference at a vertex %.2e\n", inside, worstAtVertex);
    EXPECT_LT(worstAtVertex, 1e-5);
}

// The kept state is the probes (16 hits a vertex), the cache's own per-vertex arrays and the
// records' other M − 16 hits — bounded by the records, not by vertices × M. A cropped dense floor
// (tiles of 32 × 32 cells with a block on them), M = 256.
TEST(GatherCache, KeptStateIsBoundedByTheRecords) {
    Scene scene = testscenes::tiledFloor(4, 32, Transform(), Vec3f(0.6f));
    testscenes::addPointLight(scene, Vec3f(0.3f, 1.0f, 0.2f), Vec3f(2.0f));
    const SecondPassRig rig(scene);
    const uint32_t m = 256;
    const CachedGather cached(scene, rig, m, 0.4f, smoothFirstPass(scene));
    const size_t n = scene.vertexCount(), records = cached.cache.recordCount();
    const size_t perVertex = GatherCache::kProbeRays * sizeof(GatherHit) + sizeof(uint32_t);
    // The cache's arrays: spacing, record flag, reach, normal and kRecordsPerVertex labels of 8 bytes.
    const size_t cachePerVertex = 4 + 1 + 4 + 12 + GatherCache::kRecordsPerVertex * 8;
    const size_t perRecord = (m - GatherCache::kProbeRays) * sizeof(GatherHit);
    const size_t bound = n * (perVertex + cachePerVertex) + records * perRecord * 2 + 4096;
    const size_t kept = cached.rays.bytes() + cached.cache.bytes();
    std::printf("dense floor: %zu vertices, %zu records; kept %zu bytes (%.0f a vertex; without the cache %zu a vertex)\n", n,
                records, kept, double(kept) / double(n), size_t(m) * sizeof(GatherHit));
    EXPECT_LE(kept, bound);
    EXPECT_LT(records, n / 4) << "an open floor needs few records";
    EXPECT_LT(kept, n * size_t(m) * sizeof(GatherHit) / 4);
}

// The closed sphere of FinalGather.ClosedSphereTwoPassGivesTheAnalyticIrradiance, with the cache:
// inside a closed sphere every vertex sees the same light, so interpolating it costs nothing, and
// the analytic E_d/(1 − ρ) holds as tightly as without the cache (RMS and mean within the same
// bounds; FinalGather's test derives them).
TEST(FinalGather, ClosedSphereWithTheGatherCacheGivesTheAnalyticIrradiance) {
    const double rho = 0.5, I = 1.0, R = 1.0;
    Scene scene = testscenes::closedSphere(float(R), 5, Vec3f(float(rho)));
    testscenes::addPointLight(scene, Vec3f(0.0f), Vec3f(float(I)));
    LightingSettings lighting = gatherWith(256, 0.4f);
    lighting.directSamples = 16;
    const Frame f = solveFrame(scene, lighting, 1000000);
    const size_t n = scene.vertexCount();
    ASSERT_EQ(f.out.irradiance.size(), n);
    double sum2 = 0, mean = 0;
    for (uint32_t v = 0; v < n; ++v) {
        const double e = double(f.out.irradiance[v].y) / (I / (R * R) / (1 - rho)) - 1;
        sum2 += e * e;
        mean += e / double(n);
    }
    const double rms = std::sqrt(sum2 / double(n));
    std::printf("sphere with the cache: %zu vertices, %llu records; vs 2 W/m²: RMS %.3f %%, mean %+.3f %%\n", n,
                static_cast<unsigned long long>(f.stats.gatherRecords), 100 * rms, 100 * mean);
    EXPECT_GT(f.stats.gatherRecords, 0u);
    EXPECT_LT(f.stats.gatherRecords, n / 2);
    EXPECT_LT(rms, 0.005);
    EXPECT_LT(std::abs(mean), 0.001);
}
