// Transform::isInvertible judges a matrix against its own scale (issue 23): a model built in
// micrometres is as invertible as one in metres; a flattened or non-finite one is not. A node
// matrix that is no translation, rotation and scale is refused alike on a glTF node and in a
// transform file (issue 31).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "test_support.h"
#include "util/error.h"
#include "util/vecmath.h"

using namespace qsgi;
namespace fs = std::filesystem;

TEST(Transform, InvertibilityIsRelativeToTheMatrixsOwnScale) {
    const std::array<double, 4> turn{0.2, 0.3, 0.1, std::sqrt(1 - 0.04 - 0.09 - 0.01)};
    for (double s : {1.0, 1e-5, 1e-12, 1e5, 1e12}) {
        SCOPED_TRACE(s);
        EXPECT_TRUE(Transform::fromTRS(Vec3d(1, 2, 3), turn, Vec3d(s)).isInvertible());
        EXPECT_TRUE(Transform::fromTRS(Vec3d(0.0), turn, Vec3d(s, 2 * s, 0.5 * s)).isInvertible());
        EXPECT_FALSE(Transform::fromTRS(Vec3d(0.0), turn, Vec3d(s, 0, s)).isInvertible()) << "flattened";
    }
    // Two columns almost parallel: degenerate whatever the scale.
    Transform sheared = Transform::fromTRS(Vec3d(0.0), {0, 0, 0, 1}, Vec3d(1e-5));
    sheared.at(0, 1) = 1e-5;
    sheared.at(1, 1) = 1e-5 * 1e-12;
    EXPECT_FALSE(sheared.isInvertible());
    Transform infinite = Transform::fromTRS(Vec3d(0.0), {0, 0, 0, 1}, Vec3d(1.0));
    infinite.at(0, 3) = INFINITY;
    EXPECT_FALSE(infinite.isInvertible());
}

// glTF 2.0 (§5.25): a node's matrix decomposes to translation, rotation and scale. A transform
// file's matrix is a node's local transform too, so a projective one (a last row other than
// 0 0 0 1) or a sheared one is refused there with the glTF loader's words, naming the file, the
// frame and the node, and the executable exits 2 having written nothing.
TEST(Transform, AProjectiveOrShearedMatrixInATransformFileIsRefusedAsOnAGltfNode) {
    const fs::path base = sourceDir() / "tests" / "data" / "good" / "base.gltf";
    const fs::path dir = testScratchDir("transform-matrix");
    Warnings warnings;
    const Scene scene = loadGltfScene(base.string(), warnings);
    const std::vector<std::pair<std::string, std::vector<double>>> matrices = {
        {"projective", {1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}},  // column-major: element [3] is row 3, column 0
        {"sheared", {1, 0, 0, 0, 0.5, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
    for (const auto& [name, matrix] : matrices) {
        SCOPED_TRACE(name);
        // The glTF loader's problem with the matrix on the floor's node.
        nlohmann::json gltf = nlohmann::json::parse(readFileBytes(base));
        gltf["nodes"][0]["matrix"] = matrix;
        const fs::path gltfFile = dir / (name + ".gltf");
        std::ofstream(gltfFile) << gltf.dump();
        std::string gltfProblem;
        try {
            Warnings w;
            loadGltfScene(gltfFile.string(), w);
            ADD_FAILURE() << "the glTF loader took the " << name << " matrix";
        } catch (const InputError& e) {
            EXPECT_EQ(e.place(), "nodes[0].matrix");
            gltfProblem = e.problem();
        }
        EXPECT_NE(gltfProblem.find(name == "projective" ? "last row other than 0 0 0 1" : "shears"), std::string::npos)
            << gltfProblem;

        const nlohmann::json animation = {
            {"format", "qsgi-animation"}, {"version", 1},
            {"frames", {{{"frame", 0}}, {{"frame", 7}, {"nodes", {{"Floor", {{"matrix", matrix}}}}}}}}};
        const fs::path animationFile = dir / (name + ".json");
        std::ofstream(animationFile) << animation.dump();
        try {
            Animation::fromTransformFile(animationFile.string(), scene);
            ADD_FAILURE() << "the transform file's " << name << " matrix was taken";
        } catch (const InputError& e) {
            EXPECT_EQ(e.file(), animationFile.string());
            EXPECT_EQ(e.place(), "frame 7, node 'Floor'.matrix");
            EXPECT_EQ(e.problem(), gltfProblem);
        }
        const fs::path out = dir / ("out-" + name);
        const CommandResult r = runQsgi("render " + base.string() + " --animation " + animationFile.string() +
                                        " --photons 1000 --out " + out.string());
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find(animationFile.string() + ": frame 7, node 'Floor'.matrix: " + gltfProblem), std::string::npos)
            << r.output;
        EXPECT_FALSE(fs::exists(out));
    }
    // What a transform file may still give: a zero scale (the node hidden) and a mirror.
    const nlohmann::json fine = {
        {"format", "qsgi-animation"}, {"version", 1},
        {"frames", {{{"frame", 0}, {"nodes", {{"Floor", {{"matrix", {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2, 3, 1}}}}}}},
                    {{"frame", 1}, {"nodes", {{"Floor", {{"matrix", {-1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}}}}}}}}};
    std::ofstream(dir / "fine.json") << fine.dump();
    EXPECT_NO_THROW(Animation::fromTransformFile((dir / "fine.json").string(), scene));
}
