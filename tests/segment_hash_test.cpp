// The segments themselves, pinned (issue 21): a hash of every segment in (path, bounce) order —
// origin, direction, length, power, impacted triangle and its dynamic flag, path, bounce and the
// decoded impact point — for data/cornell at 10^5 photons, at frame 0 and after five incremental
// frames, with both samplers. The constants were computed by the ray cache as it stood before
// the compact cache (issue 21); any later representation must decode to the same bits. The random
// sampler's are also what the code before the Sobol sampler (34cd1af) gives. After the
// five frames, every segment the update keeps must also equal the same (path, bounce) of a fresh
// trace of frame 5.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>
#include <cstring>

#include "pipeline/frame_solver.h"
#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "test_support.h"
#include "trace/counter_rng.h"
#include "trace/tracked_paths.h"

using namespace qsgi;

namespace {

template <class T>
uint64_t bitsOf(T value) {
    static_assert(sizeof(T) <= sizeof(uint64_t), "one word");
    uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof(T));
    return bits;
}

class SegmentHash {
public:
    void add(const Segment& s) {
        const Vec3f impact = s.impactPoint();
        for (float f : {s.origin.x, s.origin.y, s.origin.z, s.direction.x, s.direction.y, s.direction.z, s.length, s.power.x,
                        s.power.y, s.power.z, impact.x, impact.y, impact.z})
            mix(bitsOf(f));
        mix(s.triangle);
        mix(s.path);
        mix((uint64_t(s.bounce) << 8) | s.impactDynamic);
        ++count_;
    }
    uint64_t value() const { return mix64(h_ ^ count_); }

private:
    void mix(uint64_t word) { h_ = mix64(h_ ^ word) + 0x9E3779B97F4A7C15ull; }
    uint64_t h_ = 0;
    uint64_t count_ = 0;
};

struct Hashes {
    uint64_t frame0, frame5;  // frame5 == kNotMeasured: that kind of machine's has not been measured
    static constexpr uint64_t kNotMeasured = 0;
    bool matches(const Hashes& found) const {
        return frame0 == found.frame0 && (frame5 == kNotMeasured || frame5 == found.frame5);
    }
};

struct Expected {
    SamplerKind sampler;
    std::vector<Hashes> accepted;  // one pair per kind of machine (see below)
};

}  // namespace

// Pinned at 191e334 (issue 21's compact cache) and measured again when Embree was capped at AVX2
// (EmbreeDevice): the first values came from a machine whose CPU had Embree pick other kernels,
// which round differently; 191e334 and the change that capped it give these on an AVX2 machine.
// The same code (5fcc043, which passed with the first pair in CI) gives the second pair on an
// AVX-512 Xeon with Embree still capped at AVX2: the machine's own libraries (glibc's libm picks
// its kernels by CPU too) round some directions differently. Either pair is the same code's
// answer; a representation that changed any segment's bits matches neither.
// The frame-5 hash is over the tracked segments, which are the envelope's: made of a few swept
// boxes per mover instead of one (dc1510f), it tracks fewer, and this machine (the CI's) gives the
// first pair's new frame-5 values. The AVX-512 Xeon's have not been measured since, so there only
// frame 0 is compared (each kept segment is still checked against a fresh trace, bit for bit).
TEST(SegmentHash, CornellSegmentsKeepTheirBitsAtFrameZeroAndAfterFiveIncrementalFrames) {
    const Expected cases[] = {
        {SamplerKind::Sobol, {{0xf0132fa94cf244b7ull, 0x31a2d14087005af8ull}, {0x6048c72dedfdb848ull, Hashes::kNotMeasured}}},
        {SamplerKind::Random, {{0x75a3e5941d325fdaull, 0x8784e905da1cfec1ull}, {0x5aaff41604968e44ull, Hashes::kNotMeasured}}}};
    const std::string dir = (sourceDir() / "data/cornell").string();
    for (const Expected& expected : cases) {
        SCOPED_TRACE(samplerName(expected.sampler));
        Warnings w;
        Scene scene = loadGltfScene(dir + "/cornell.gltf", w);
        const Animation animation = Animation::fromTransformFile(dir + "/animation.json", scene);
        scene.setRestPose(animation.poseAt(0));
        scene.markDynamic(animation.movedNodes(), animation.morphedNodes());
        sweepAnimationBounds(scene, animation);
        scene.applyPose(scene.restPose());

        FrameSolverSettings settings;
        settings.estimator.kind = EstimatorKind::Detp;
        settings.estimator.radius = 0.05f;
        settings.trace.photons = 100000;
        settings.trace.seed = 1;
        settings.trace.sampling = PhotonSampling{expected.sampler, 2};
        settings.update.alwaysUpdate = true;
        EmbreeDevice device;
        FrameSolver solver(scene, device, settings);

        solver.solve(animation.poseAt(0));
        const RayCache frame0 = solver.tracer().traceAll();
        SegmentHash h0;
        frame0.forEachSegment([&](const Segment& s) { h0.add(s); });
        // Decoded to those bits from at most 32 bytes a segment, records and path index together.
        EXPECT_LE(double(frame0.bytes()) / double(frame0.segmentCount()), 32.0);

        for (int f = 1; f <= 5; ++f) {
            ASSERT_FALSE(solver.solve(animation.poseAt(f)).record.fromScratch) << "frame " << f;
        }
        ASSERT_NE(solver.trackedPaths(), nullptr);
        std::vector<Segment> kept;
        solver.trackedPaths()->allSegments(kept);
        ASSERT_GT(kept.size(), 1000u);
        SegmentHash h5;
        const RayCache fresh = solver.tracer().traceAll();  // frame 5's pose, the solver's BVH
        std::vector<Segment> path;
        for (const Segment& s : kept) {
            h5.add(s);
            ASSERT_LT(s.path, fresh.pathCount());
            path.clear();
            fresh.appendPath(s.path, path);
            ASSERT_LT(s.bounce, path.size()) << "path " << s.path << " bounce " << s.bounce;
            SegmentHash one, other;
            one.add(path[s.bounce]);
            other.add(s);
            ASSERT_EQ(one.value(), other.value()) << "path " << s.path << " bounce " << s.bounce;
        }
        std::printf("%s: frame 0 %zu segments, hash 0x%016llx; after five frames %zu kept segments, hash 0x%016llx\n",
                    samplerName(expected.sampler), size_t(frame0.segmentCount()), static_cast<unsigned long long>(h0.value()),
                    kept.size(), static_cast<unsigned long long>(h5.value()));
        const Hashes found{h0.value(), h5.value()};
        EXPECT_TRUE(std::any_of(expected.accepted.begin(), expected.accepted.end(), [&](const Hashes& h) { return h.matches(found); }))
            << "neither pinned pair of hashes";
    }
}
