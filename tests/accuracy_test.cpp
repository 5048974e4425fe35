// The accuracy tooling: error statistics, border vertices, and `qsgi compare` end to end.
#include <gtest/gtest.h>

#include <filesystem>

#include "estimate/accuracy.h"
#include "estimate/impact_count.h"
#include "output/ply_reader.h"
#include "output/output_directory.h"
#include "output/ply_writer.h"
#include "test_support.h"

using namespace qsgi;
namespace fs = std::filesystem;

TEST(Accuracy, ErrorStatsOfAKnownDifference) {
    const std::vector<Vec3f> reference(100, Vec3f(2.0f));
    std::vector<Vec3f> values(100, Vec3f(2.0f));
    for (size_t v = 0; v < 100; ++v) values[v] = Vec3f(v % 2 ? 2.2f : 1.8f);  // ±10 %, no bias
    const ErrorStats s = errorStats(values, reference);
    EXPECT_EQ(s.vertices, 100u);
    EXPECT_NEAR(s.relativeRms, 0.1, 1e-6);
    EXPECT_NEAR(s.relativeBias, 0.0, 1e-6);
    const ErrorStats biased = errorStats(std::vector<Vec3f>(100, Vec3f(2.1f)), reference);
    EXPECT_NEAR(biased.relativeBias, 0.05, 1e-6);
    EXPECT_NEAR(biased.relativeRms, 0.05, 1e-6);
}

TEST(Accuracy, BorderVerticesAreThoseNearTheCrease) {
    const Scene corner = testscenes::corner(20, Vec3f(0.5f));  // 0.1 m spacing, crease along z = y = 0
    const auto near = verticesNearCreases(corner.positions, corner.normals, 0.15f);
    for (size_t v = 0; v < corner.vertexCount(); ++v) {
        const Vec3d p = Vec3d(corner.positions[v]) + corner.worldOrigin;
        const double distance = corner.normals[v].y > 0.5f ? p.z : p.y;
        EXPECT_EQ(near[v], distance <= 0.15 + 1e-6) << "vertex " << v << " at distance " << distance;
    }
}

// Near-edge vertices are those whose exact distance to an open edge is within the radius, at any
// radius: from 1e-6 of the plane (where sampling edges every radius/8 once made 10^8 samples and
// took minutes) to larger than the whole plane.
TEST(Accuracy, NearEdgeRegionsEqualExactDistancesAtEveryRadius) {
    const Scene plane = testscenes::plane(1.0f, 10, Vec3f(0.5f));  // 2 m square, 0.2 m spacing, open border
    Bounds3f bounds;
    for (const Vec3f& p : plane.positions) bounds.extend(p);
    const int flat = bounds.upper.y - bounds.lower.y < 1e-6f ? 1 : bounds.upper.z - bounds.lower.z < 1e-6f ? 2 : 0;
    for (float radius : {2e-6f, 0.25f, 0.5f, 0.9f, 10.0f}) {
        SCOPED_TRACE("radius " + std::to_string(radius));
        const std::vector<EdgeRegion> region = edgeRegions(plane.positions, plane.normals, plane.triangles, radius);
        for (size_t v = 0; v < plane.vertexCount(); ++v) {
            float toBorder = 1e30f;
            for (int axis = 0; axis < 3; ++axis)
                if (axis != flat)
                    toBorder = std::min({toBorder, plane.positions[v][axis] - bounds.lower[axis],
                                         bounds.upper[axis] - plane.positions[v][axis]});
            const EdgeRegion expected = toBorder < 1e-5f           ? EdgeRegion::OnEdge
                                        : toBorder <= radius + 1e-5f ? EdgeRegion::NearEdge
                                                                     : EdgeRegion::Interior;
            EXPECT_EQ(int(region[v]), int(expected)) << "vertex " << v << " at " << toBorder << " m from the border";
        }
    }
}

TEST(Accuracy, CompareCommandReadsPlysAndRejectsMismatches) {
    const fs::path dir = testScratchDir("compare");
    Scene scene = testscenes::plane(1.0f, 10, Vec3f(0.5f));
    VertexRadiosity a, b;
    a.radiosity.assign(scene.vertexCount(), Vec3f(1.0f));
    b.radiosity.assign(scene.vertexCount(), Vec3f(1.1f));
    a.irradiance.assign(scene.vertexCount(), Vec3f(2.0f));
    b.irradiance.assign(scene.vertexCount(), Vec3f(2.2f));
    writeFileAtomically(dir / "a.ply", encodeVertexRadiosityPly(scene, a, PreviewTonemap{}));
    writeFileAtomically(dir / "b.ply", encodeVertexRadiosityPly(scene, b, PreviewTonemap{}));
    const VertexRadiosityPly back = readVertexRadiosityPly((dir / "b.ply").string());
    ASSERT_EQ(back.radiosity.size(), scene.vertexCount());
    EXPECT_EQ(back.radiosity[5], Vec3f(1.1f));
    EXPECT_EQ(back.irradiance[5], Vec3f(2.2f));
    EXPECT_EQ(back.normals[5], scene.normals[5]);

    const CommandResult r = runQsgi("compare " + (dir / "b.ply").string() + " " + (dir / "a.ply").string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("\"relative_bias\": 0.1"), std::string::npos) << r.output;

    Scene other = testscenes::plane(1.0f, 4, Vec3f(0.5f));
    VertexRadiosity c;
    c.radiosity.assign(other.vertexCount(), Vec3f(1.0f));
    c.irradiance.assign(other.vertexCount(), Vec3f(2.0f));
    writeFileAtomically(dir / "c.ply", encodeVertexRadiosityPly(other, c, PreviewTonemap{}));
    const CommandResult mismatch = runQsgi("compare " + (dir / "c.ply").string() + " " + (dir / "a.ply").string());
    EXPECT_EQ(mismatch.exitCode, 2);
    EXPECT_NE(mismatch.output.find("not the same scene"), std::string::npos) << mismatch.output;
    const CommandResult notPly = runQsgi("compare " + (sourceDir() / "README.md").string() + " " + (dir / "a.ply").string());
    EXPECT_EQ(notPly.exitCode, 2);
    EXPECT_NE(notPly.output.find("not a PLY"), std::string::npos) << notPly.output;
}

// A reference of a vertex subset (scripts/reference.py --vertices N) flags the vertices it holds
// in a `referenced` property; `qsgi compare` judges the solution on those alone, by the same
// regions (decided on the whole mesh). The unflagged vertices hold garbage that would show.
TEST(Accuracy, CompareJudgesASubsetReferenceOnItsSubsetAlone) {
    const fs::path dir = testScratchDir("compare-subset");
    const Scene scene = testscenes::corner(8, Vec3f(0.5f));
    const size_t n = scene.vertexCount();
    VertexRadiosity solution;
    solution.radiosity.assign(n, Vec3f(1.0f));
    solution.irradiance.assign(n, Vec3f(2.0f));
    writeFileAtomically(dir / "solution.ply", encodeVertexRadiosityPly(scene, solution, PreviewTonemap{}));
    // The reference: 1.25 at every third vertex (flagged), 100 elsewhere (not).
    std::vector<bool> flagged(n);
    std::vector<Vec3f> reference(n);
    for (size_t v = 0; v < n; ++v) {
        flagged[v] = v % 3 == 0;
        reference[v] = Vec3f(flagged[v] ? 1.25f : 100.0f);
    }
    std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(n) +
                      "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\n"
                      "property float nz\nproperty float radiosity_r\nproperty float radiosity_g\nproperty float radiosity_b\n"
                      "property uchar referenced\nelement face " + std::to_string(scene.triangleCount()) +
                      "\nproperty list uchar int vertex_indices\nend_header\n";
    auto put = [&](const void* bytes, size_t size) { ply.append(static_cast<const char*>(bytes), size); };
    for (size_t v = 0; v < n; ++v) {
        put(&scene.positions[v], sizeof(Vec3f));
        put(&scene.normals[v], sizeof(Vec3f));
        put(&reference[v], sizeof(Vec3f));
        const uint8_t flag = flagged[v];
        put(&flag, 1);
    }
    for (const Triangle& t : scene.triangles) {
        const uint8_t three = 3;
        put(&three, 1);
        for (uint32_t i : t.v) {
            const int32_t index = int32_t(i);
            put(&index, 4);
        }
    }
    writeFileAtomically(dir / "subset.ply", ply);
    const VertexRadiosityPly back = readVertexRadiosityPly((dir / "subset.ply").string());
    ASSERT_EQ(back.referenced.size(), n);
    EXPECT_EQ(back.referenced[3], 1);
    EXPECT_EQ(back.referenced[4], 0);

    const CommandResult r = runQsgi("compare " + (dir / "solution.ply").string() + " " + (dir / "subset.ply").string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const nlohmann::json j = nlohmann::json::parse(r.output);
    // 1 against 1.25 at every flagged vertex: bias and RMS −0.2 and 0.2 in every region it has.
    EXPECT_EQ(j["all"]["vertices"].get<size_t>(), (n + 2) / 3);
    for (const char* region : {"all", "edge", "near_edge", "interior"}) {
        if (j[region]["vertices"].get<size_t>() == 0) continue;
        EXPECT_NEAR(j[region]["relative_bias"].get<double>(), -0.2, 1e-6) << region;
        EXPECT_NEAR(j[region]["relative_rms"].get<double>(), 0.2, 1e-6) << region;
    }
    EXPECT_GT(j["edge"]["vertices"].get<size_t>() + j["near_edge"]["vertices"].get<size_t>(), 0u);
}
