// Every hostile file in tests/data/bad/ (made by tests/data/make_inputs.py, or found by fuzzing)
// is refused by the qsgi executable with one line naming the file and the problem, exit code 2
// and nothing written; every valid edge case in tests/data/good/ loads with the geometry it holds.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <functional>
#include <map>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include <sys/stat.h>

#include "output/ply_reader.h"
#include "output/folder_survey.h"
#include "pipeline/render_job.h"
#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "test_support.h"
#include "util/memory.h"

using namespace qsgi;
namespace fs = std::filesystem;

namespace {

struct HostileFile {
    std::string kind;   // gltf, animation, config or ply
    std::string file;   // relative to tests/data
    std::string words;  // the message must contain these
    std::string names;  // and name this file
};

fs::path dataDir() { return sourceDir() / "tests" / "data"; }

std::vector<HostileFile> readTable(const fs::path& tsv) {
    std::vector<HostileFile> rows;
    std::ifstream in(tsv);
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') continue;
        std::vector<std::string> cells;
        std::stringstream fields(line);
        for (std::string cell; std::getline(fields, cell, '\t');) cells.push_back(cell);
        if (cells.size() != 4) ADD_FAILURE() << tsv << ": a row needs 4 tab-separated cells: " << line;
        else rows.push_back({cells[0], cells[1], cells[2], cells[3]});
    }
    return rows;
}

std::vector<HostileFile> allHostileFiles() {
    std::vector<HostileFile> rows = readTable(dataDir() / "bad" / "generated.tsv");
    const std::vector<HostileFile> found = readTable(dataDir() / "bad" / "found.tsv");
    rows.insert(rows.end(), found.begin(), found.end());
    return rows;
}

}  // namespace

TEST(HostileInput, EveryFileInTheBadFolderIsListedWithItsExpectedMessage) {
    std::set<std::string> listed;
    for (const HostileFile& row : allHostileFiles()) {
        EXPECT_TRUE(fs::exists(dataDir() / row.file)) << row.file << " is listed but absent";
        EXPECT_TRUE(listed.insert(row.file).second) << row.file << " is listed twice";
    }
    size_t files = 0;
    for (const auto& entry : fs::recursive_directory_iterator(dataDir() / "bad")) {
        if (!entry.is_regular_file() || entry.path().extension() == ".tsv") continue;
        ++files;
        const std::string rel = fs::relative(entry.path(), dataDir()).generic_string();
        EXPECT_TRUE(listed.count(rel)) << rel << " is in tests/data/bad but in neither generated.tsv nor found.tsv";
    }
    EXPECT_GE(files, 100u);
}

// The files are independent (each row its own output folder) and a refusal's cost is the
// executable's start (its shared libraries), so the rows run a few at a time, one per core; every
// row's result is then checked here as it was when they ran one after another.
TEST(HostileInput, EveryBadFileIsRefusedWithOneLineNamingItExitTwoAndNothingWritten) {
    const fs::path scratch = testScratchDir("hostile");
    const std::string base = (dataDir() / "good" / "base.gltf").string();
    const std::vector<HostileFile> rows = allHostileFiles();
    std::vector<std::string> commands(rows.size());
    std::vector<fs::path> outs(rows.size());
    for (size_t i = 0; i < rows.size(); ++i) {
        const HostileFile& row = rows[i];
        const std::string file = (dataDir() / row.file).string();
        outs[i] = scratch / ("out" + std::to_string(i));
        std::string args;
        if (row.kind == "gltf") args = "render " + file + " --photons 1000";
        else if (row.kind == "animation") args = "render " + base + " --animation " + file + " --photons 1000";
        else if (row.kind == "config") args = "render --config " + file;  // the config's own photon count
        else if (row.kind == "ply") args = "compare " + file + " " + (dataDir() / "good" / "frame.ply").string();
        else {
            ADD_FAILURE() << row.file << ": unknown kind " << row.kind;
            continue;
        }
        commands[i] = args + (row.kind == "ply" ? "" : " --out " + outs[i].string());
    }
    std::vector<CommandResult> results(rows.size());
    std::atomic<size_t> next{0};
    std::vector<std::thread> workers;
    for (unsigned w = 0; w < std::max(2u, std::thread::hardware_concurrency()); ++w)
        workers.emplace_back([&] {
            for (size_t i; (i = next++) < rows.size();)
                if (!commands[i].empty()) results[i] = runQsgi(commands[i]);
        });
    for (std::thread& worker : workers) worker.join();
    for (size_t i = 0; i < rows.size(); ++i) {
        if (commands[i].empty()) continue;
        const HostileFile& row = rows[i];
        const CommandResult& r = results[i];
        SCOPED_TRACE(row.file + "\n" + r.output);
        EXPECT_EQ(r.exitCode, 2);
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line expected";
        EXPECT_EQ(r.output.rfind("qsgi: error: ", 0), 0u);
        EXPECT_NE(r.output.find(row.words), std::string::npos) << "the message should say '" << row.words << "'";
        EXPECT_NE(r.output.find(row.names), std::string::npos) << "the message should name " << row.names;
        EXPECT_FALSE(fs::exists(outs[i])) << "a refused input must write nothing";
    }
}

// Valid files that tinygltf alone refuses or misreads.
TEST(HostileInput, ValidEdgeCasesLoadWithTheGeometryTheyHold) {
    const std::vector<Vec3f> floor = {{-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}};
    for (const char* name : {"base.gltf", "accessor_without_bufferview.gltf", "buffer_gltf_buffer_data_uri.gltf",
                             "buffer_without_uri_unused.gltf", "quantized.gltf", "glb_with_unused_second_buffer.glb",
                             "texture_embedded.gltf", "texture_data_uri.gltf", "texture_unreadable.gltf",
                             "integer_written_as_float.gltf", "data_uri_percent_encoded.gltf", "glb_trailing_bytes.glb",
                             "primitive_without_position.gltf", "light_range_and_texture_transform.gltf",
                             "texture_png_hostile.gltf", "texture_png_variants.gltf"}) {
        SCOPED_TRACE(name);
        Warnings warnings;
        Scene scene;
        ASSERT_NO_THROW(scene = loadGltfScene((dataDir() / "good" / name).string(), warnings));
        ASSERT_EQ(scene.triangleCount(), 2u);
        ASSERT_EQ(scene.positions.size(), 4u);
        ASSERT_EQ(scene.lights.size(), 1u);
        // Positions are re-centred on the scene's origin (worldOrigin) for precision.
        for (size_t v = 0; v < 4; ++v) {
            const Vec3d world = Vec3d(scene.positions[v]) + scene.worldOrigin;
            // Quantized: -32767/32767 is exactly -1; floats are exact.
            EXPECT_NEAR(world.x, floor[v].x, 1e-6) << "vertex " << v;
            EXPECT_NEAR(world.y, floor[v].y, 1e-6) << "vertex " << v;
            EXPECT_NEAR(world.z, floor[v].z, 1e-6) << "vertex " << v;
            EXPECT_NEAR(scene.normals[v].y, 1.0f, 1e-6f) << "vertex " << v;
        }
    }
}

// Issue 23: what a file cannot say. A folder given as a transform file, and a request beyond
// what this process may use although the machine has it (ulimit -v; a container's or a Slurm
// job's control group is read the same way, usableMemory in lib/util/memory.cpp).
TEST(HostileInput, AFolderAsATransformFileIsRefusedByName) {
    const std::string base = (dataDir() / "good" / "base.gltf").string();
    const CommandResult r = runQsgi("render " + base + " --animation " + dataDir().string() + " --photons 1000 --out " +
                                    (fs::path(testScratchDir("hostile-folder")) / "out").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("is a directory"), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

// Every file qsgi reads goes through one opening rule (util/input_file.h): a named pipe or a
// device given as the scene, the transform file, a config, an environment map or a PLY to compare
// is refused at once by its kind — exit 2, one line naming the path, nothing written — where it
// used to wait for a writer or read /dev/zero's endless bytes until killed. Each run is given 30 s
// by `timeout` (exit 124 when it hangs), far beyond the second a refusal takes.
TEST(HostileInput, APipeOrADeviceAsAnyInputIsRefusedByItsKindWithoutWaiting) {
    const fs::path dir = testScratchDir("hostile-not-regular");
    const fs::path pipe = dir / "pipe.exr", out = dir / "out";
    fs::remove(pipe);
    ASSERT_EQ(mkfifo(pipe.c_str(), 0600), 0);
    const std::string base = (dataDir() / "good" / "base.gltf").string();
    const std::string good = (sourceDir() / "tests" / "reference" / "cornell_f0000.ply").string();
    for (const std::string& path : {pipe.string(), std::string("/dev/zero")}) {
        const std::string kind = path == "/dev/zero" ? "is a device, not a regular file" : "is a named pipe, not a regular file";
        const std::vector<std::string> runs = {
            "render " + path + " --out " + out.string(),
            "render " + base + " --animation " + path + " --out " + out.string(),
            "render --config " + path + " --out " + out.string(),
            "render " + base + " --environment " + path + " --photons 1000 --out " + out.string(),
            "compare " + path + " " + good,
        };
        for (const std::string& run : runs) {
            SCOPED_TRACE(run);
            fs::remove_all(out);
            const CommandResult r = runCommand("timeout 30 " + std::string(QSGI_CLI) + " " + run);
            EXPECT_EQ(r.exitCode, 2) << r.output;
            EXPECT_NE(r.output.find(path + ": " + kind), std::string::npos) << r.output;
            EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
            EXPECT_FALSE(fs::exists(out / "frame_0000.ply"));
        }
    }
    fs::remove(pipe);
}

namespace {
// A glTF of grey quads facing +y (each four corners, x then z), the last `emissive` of them lit at
// radiance `strength` (KHR_materials_emissive_strength).
void writeQuads(const std::string& path, const std::vector<std::vector<float>>& quads, size_t emissive, double strength) {
    testscenes::GltfWriter w;
    using nlohmann::json;
    json primitives = json::array();
    for (size_t q = 0; q < quads.size(); ++q) {
        const int positions = w.accessor(quads[q], "VEC3");
        const int indices = w.indices({0, 1, 2, 0, 2, 3});
        const bool lit = q + emissive >= quads.size();
        primitives.push_back({{"attributes", {{"POSITION", positions}}}, {"indices", indices}, {"material", lit ? 1 : 0}});
    }
    w.doc["scenes"] = {{{"nodes", {w.node({{"name", "Quads"}, {"mesh", 0}})}}}};
    w.doc["meshes"] = json::array({{{"primitives", primitives}}});
    w.doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
    w.doc["materials"] = json::array(
        {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}}}},
         {{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}}}, {"emissiveFactor", {1, 1, 1}},
          {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", strength}}}}}}});
    w.write(path);
}
std::vector<float> square(float half, float y = 0) { return {-half, y, half, half, y, half, half, y, -half, -half, y, -half}; }
}  // namespace

// Lights checked by what reaches the output (issue 48): a sky of 3·10³⁸ over a 2 µm floor and a
// sliver of 10⁻³⁰ m² lit at 2·10³⁸ carry little power (2.4·10²⁸ W, 3·10⁸ W) but their πL
// overflows float: refused before the render, naming the light. A point light a micrometre over
// a floor corner passes every check made before the render (its power is 8.8·10²⁹ W) but I/d² is
// 7·10⁴⁰: the frame's own guard refuses it — exit 2, nothing written, never a file with Inf. And a
// spot light's direction [0, −10³⁰, 0], whose squares overflow float, is a direction: it renders.
TEST(HostileInput, LightsWhoseRadianceOrIrradianceOverflowsAreRefusedAndALargeDirectionIsADirection) {
    const fs::path dir = testScratchDir("hostile-overflow");
    const std::string tiny = (dir / "tiny.gltf").string(), sliver = (dir / "sliver.gltf").string();
    writeQuads(tiny, {square(1e-6f)}, 0, 1);
    // The sliver: 1 m long, 10⁻³⁰ m wide, over a 1 m floor.
    writeQuads(sliver, {square(0.5f), {-0.5f, 0.1f, 0, 0.5f, 0.1f, 0, 0.5f, 0.1f, -1e-30f, -0.5f, 0.1f, -1e-30f}}, 1, 2e38);
    const fs::path out = dir / "out";
    struct Case {
        std::string arguments, message;
    };
    const std::string config = (dir / "close.json").string(), spot = (dir / "spot.json").string();
    { std::ofstream(config) << R"({"lights": [{"type": "point", "position": [1, 1e-6, 1], "intensity": [7e28, 7e28, 7e28]}]})"; }
    { std::ofstream(spot) << R"({"lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1e30, 0], "intensity": [10, 10, 10]}]})"; }
    const std::vector<Case> cases = {
        {tiny + " --sky 3e38", "the sky or environment map: has a radiance of 3e+38"},
        {sliver, "has a radiance of 2e+38"},
        {(dataDir() / "good" / "base.gltf").string() + " --radius 1 --config " + config, "its light is beyond float's range"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.arguments);
        fs::remove_all(out);
        const CommandResult r = runQsgi("render " + c.arguments + " --photons 1000 --no-exr --out " + out.string());
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
        EXPECT_FALSE(fs::exists(out / "frame_0000.ply"));
        // A frame refused by the last guard leaves the folder as an interrupted run does: its log
        // lists no frame.
        if (fs::exists(out / "timing.json")) {
            EXPECT_TRUE(nlohmann::json::parse(readFileBytes(out / "timing.json"))["frames"].empty());
        }
    }
    fs::remove_all(out);
    const CommandResult lit = runQsgi("render " + (dataDir() / "good" / "base.gltf").string() + " --config " + spot +
                                      " --photons 1000 --no-exr --quiet --out " + out.string());
    EXPECT_EQ(lit.exitCode, 0) << lit.output;
    EXPECT_TRUE(fs::exists(out / "frame_0000.ply"));
}

// One memory budget, read from the address-space limit (issue 48), consulted before what grows
// with the input is allocated: an environment map whose header claims 12288 x 6144 pixels (its
// loading would hold 3.1 GiB), --subdivide making more triangles than 1.5 GiB holds at 256 bytes
// each (counted as bisection makes them: the estimate passes), and an asset whose buffers declare
// 3.3 GiB, and a gather keeping 65536 hits a vertex between frames. Each is refused naming the
// input, what it would need and the limit; exit 2; nothing written. A buffer of 5·10⁹ bytes is
// beyond a GLB's 4 GiB whatever the memory.
TEST(HostileInput, InputsBeyondTheMemoryBudgetAreRefusedBeforeTheyAreAllocated) {
    if (kSanitized) GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space, so ulimit -v cannot apply";
    const fs::path dir = testScratchDir("hostile-budget"), out = dir / "out";
    const std::string base = (dataDir() / "good" / "base.gltf").string();
    // A Radiance header and no pixels: refused before they are read.
    { std::ofstream(dir / "big.hdr", std::ios::binary) << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 6144 +X 12288\n"; }
    nlohmann::json doc = nlohmann::json::parse(readFileBytes(base));
    doc["buffers"].push_back({{"byteLength", 3500000000ull}});
    { std::ofstream(dir / "declared.gltf") << doc.dump(); }
    doc["buffers"].back()["byteLength"] = 5000000000ull;
    { std::ofstream(dir / "beyond.gltf") << doc.dump(); }
    struct Case {
        std::string limit, arguments, message;
    };
    const std::vector<Case> cases = {
        {"3145728", base + " --environment " + (dir / "big.hdr").string(),
         "big.hdr: an environment map of 12288 x 6144 pixels would need 3.1 GiB, more than the 3.0 GiB of memory ulimit -v allows"},
        {"1572864", base + " --subdivide 0.0005", "subdivide (--subdivide): 0.0005 would make more than 6291456 triangles"},
        {"3145728", (dir / "declared.gltf").string() + " --gltf-out",
         "declared.gltf: buffers: asset.glb (--gltf-out: the scene's buffers, 3.3 GiB, and the bake) would need 3.3 GiB, more than "
         "the 3.0 GiB of memory ulimit -v allows"},
        {"", (dir / "beyond.gltf").string() + " --gltf-out", "beyond the 4 GiB a GLB file holds"},
        // 21,636 vertices keeping 65536 hits of 16 bytes each between frames: 21 GiB.
        {"3145728", (sourceDir() / "data" / "cornell" / "cornell.gltf").string() + " --animation " +
                        (sourceDir() / "data" / "cornell" / "animation.json").string() + " --frames 0:1 --gather 65536 --gather-cache off",
         "gather (--gather): the gather's kept hits (65536 a vertex, at 16 bytes, for 21636 vertices) would need 21.1 GiB"},
    };
    // The messages name ulimit -v as the limit that binds: not so where another is lower already
    // (a container's or a Slurm job's control group). Such a case cannot be checked here; the
    // others still are, and the test then ends as skipped, naming what it did not run, so that it
    // never passes having checked less.
    std::vector<std::string> notRun;
    for (const Case& c : cases) {
        SCOPED_TRACE(c.arguments);
        if (!c.limit.empty() && usableMemory().bytes < uint64_t(std::stoull(c.limit)) * 1024) {
            notRun.push_back("ulimit -v " + c.limit + ": " + c.arguments);
            continue;
        }
        fs::remove_all(out);
        const CommandResult r = runCommand((c.limit.empty() ? std::string() : "ulimit -v " + c.limit + " && ") + QSGI_CLI +
                                           " render " + c.arguments + " --radius 1 --photons 1000 --no-exr --out " + out.string());
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
        EXPECT_FALSE(fs::exists(out));
    }
    if (!notRun.empty()) {
        std::string list;
        for (const std::string& n : notRun) list += "\n  " + n;
        GTEST_SKIP() << notRun.size() << " of " << cases.size() << " cases not run: this process may use only "
                     << formatBytes(usableMemory().bytes) << ", less than the ulimit -v their messages name as the limit:" << list;
    }
}

// A zero scale in a transform file hides the node for that frame (glTF's visibility, docs/design.md
// §3; issue 23: it was refused as "not invertible"), on every axis or on one; the frame after it
// shows the floor lit again, exactly as frame 0 (the same pose, the same photons).
TEST(HostileInput, AZeroScaleInATransformFileHidesTheNode) {
    const std::string base = (dataDir() / "good" / "base.gltf").string();
    const fs::path dir = testScratchDir("hostile-zero-scale");
    const fs::path animation = dir / "hide.json";
    {
        std::ofstream f(animation);
        f << R"({"format":"qsgi-animation","version":1,"frames":[{"frame":0},)"
          << R"({"frame":1,"nodes":{"Floor":{"scale":[0,0,0]}}},{"frame":2,"nodes":{"Floor":{"scale":[1,0,1]}}},)"
          << R"({"frame":3,"nodes":{"Floor":{"scale":[1,1,1]}}}]})";
    }
    const CommandResult r = runQsgi("render " + base + " --animation " + animation.string() +
                                    " --photons 20000 --quiet" + kCheapSecondPass + " --out " + (dir / "out").string());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    std::vector<VertexRadiosityPly> frames;
    for (int f = 0; f < 4; ++f) frames.push_back(readVertexRadiosityPly((dir / "out" / frameFileName(f, "ply")).string()));
    for (int f = 0; f < 4; ++f) {
        SCOPED_TRACE("frame " + std::to_string(f));
        const bool hidden = f == 1 || f == 2;
        for (size_t v = 0; v < frames[size_t(f)].radiosity.size(); ++v) {
            const Vec3f b = frames[size_t(f)].radiosity[v];
            ASSERT_TRUE(isFinite(b) && isFinite(frames[size_t(f)].normals[v]));
            if (hidden) {
                EXPECT_EQ(maxComponent(b), 0.0f) << v;
                EXPECT_EQ(frames[size_t(f)].normals[v].y, 1.0f) << "the last finite normal is kept";
            } else {
                EXPECT_GT(b.y, 0.0f) << v;
                EXPECT_EQ(b.y, frames[0].radiosity[v].y) << v;
            }
        }
    }
}

// The contract of issue 23: an error in an object the render reads is exit 2 naming it; the
// same error in an object nothing reads is a warning naming it; --strict refuses those too.
TEST(HostileInput, ErrorsInUnusedObjectsWarnAndStrictRefusesThem) {
    nlohmann::json doc = nlohmann::json::parse(readFileBytes(dataDir() / "good" / "base.gltf"));
    doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 1.0}, {"zfar", 0.5}}}}};
    doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {2, 1, 1, 1}}}}}};
    nlohmann::json beyond = doc["accessors"][0];
    beyond["byteOffset"] = 4000;  // past the end of its view
    doc["accessors"].push_back(beyond);
    nlohmann::json noBounds = doc["accessors"][0];
    noBounds.erase("min");
    noBounds.erase("max");
    doc["accessors"].push_back(noBounds);
    const int noBoundsAccessor = int(doc["accessors"].size()) - 1;
    doc["meshes"].push_back({{"primitives", {{{"attributes", {{"POSITION", noBoundsAccessor}}}, {"material", 0}}}}});
    doc["nodes"].push_back({{"name", "Sheared"}, {"matrix", {1, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}});
    const std::map<std::string, std::string> unused = {
        {"cameras[0]", "zfar"}, {"materials[0]", "baseColorFactor"}, {"accessors[" + std::to_string(noBoundsAccessor - 1) + "]", "past the end"},
        {"meshes[1]", "min and max"}, {"nodes[2]", "shears"}};
    const fs::path dir = testScratchDir("hostile-unused");
    auto write = [&](const std::string& name, const nlohmann::json& d) {
        std::ofstream(dir / name) << d.dump();
        return (dir / name).string();
    };
    const std::string file = write("unused.gltf", doc);
    const CommandResult lenient = runQsgi("inspect " + file);
    ASSERT_EQ(lenient.exitCode, 0) << lenient.output;
    for (const auto& [object, rule] : unused) {
        const size_t at = lenient.output.find(object + " is not in the rendered scene");
        EXPECT_NE(at, std::string::npos) << object << "\n" << lenient.output;
        const size_t lineStart = lenient.output.rfind('\n', at);
        EXPECT_NE(lenient.output.substr(lineStart, at - lineStart).find(rule), std::string::npos) << object << ": " << rule;
    }
    const CommandResult strict = runQsgi("inspect --strict " + file);
    EXPECT_EQ(strict.exitCode, 2) << strict.output;
    EXPECT_NE(strict.output.find("--strict refuses it"), std::string::npos) << strict.output;
    EXPECT_EQ(std::count(strict.output.begin(), strict.output.end(), '\n'), 1) << strict.output;

    // Put each object where the render reads it: refused without --strict, naming it.
    auto used = [&](const std::string& name, const std::function<void(nlohmann::json&)>& edit, const std::string& names) {
        nlohmann::json d = doc;
        edit(d);
        const CommandResult r = runQsgi("inspect " + write(name, d));
        EXPECT_EQ(r.exitCode, 2) << name << ": " << r.output;
        EXPECT_NE(r.output.find(names), std::string::npos) << name << ": " << r.output;
        EXPECT_EQ(r.output.find("not in the rendered scene"), std::string::npos) << name << ": " << r.output;
    };
    used("camera.gltf", [](nlohmann::json& d) { d["nodes"][0]["camera"] = 0; }, "cameras[0]");
    used("material.gltf", [](nlohmann::json& d) { d["meshes"][0]["primitives"][0]["material"] = 0; }, "materials[0]");
    used("mesh.gltf", [](nlohmann::json& d) { d["nodes"][0]["mesh"] = 1; }, "min and max");
    used("node.gltf", [](nlohmann::json& d) { d["scenes"][0]["nodes"].push_back(2); }, "nodes[2]");
}

// A hidden node is fine; a hidden camera has no direction to look in: refused before any frame
// is written, naming the frame.
TEST(HostileInput, ACameraScaledToZeroIsRefusedNamingTheFrame) {
    nlohmann::json doc = nlohmann::json::parse(readFileBytes(dataDir() / "good" / "base.gltf"));
    doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
    doc["nodes"].push_back({{"name", "Cam"}, {"camera", 0}, {"translation", {0, 0.5, 3}}});
    doc["scenes"][0]["nodes"].push_back(int(doc["nodes"].size()) - 1);
    const fs::path dir = testScratchDir("hostile-camera-zero");
    std::ofstream(dir / "scene.gltf") << doc.dump();
    std::ofstream(dir / "hide.json") << R"({"format":"qsgi-animation","version":1,"frames":[{"frame":0},)"
                                     << R"({"frame":2,"nodes":{"Cam":{"scale":[0,0,0]}}}]})";
    const CommandResult r = runQsgi("render " + (dir / "scene.gltf").string() + " --animation " + (dir / "hide.json").string() +
                                    " --photons 1000 --out " + (dir / "out").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("frame 2"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("'Cam'"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out")) << "nothing may be written";
}

TEST(HostileInput, MemoryBeyondTheProcesssLimitIsRefusedNamingTheLimit) {
    if (kSanitized) GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space, so ulimit -v cannot apply";
    const std::string base = (dataDir() / "good" / "base.gltf").string();
    // 400 million photons need at least 4.8 GB of ray cache: within this machine's memory, not
    // within a 3 GiB address space.
    const CommandResult r = runCommand("ulimit -v 3145728 && " + std::string(QSGI_CLI) + " render " + base +
                                       " --photons 400000000 --out " +
                                       (fs::path(testScratchDir("hostile-ulimit")) / "out").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("ulimit -v"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("--photons"), std::string::npos) << r.output;
}

// Hierarchies and transform files of any length load in linear time and without recursion
// (issue 23: a chain of 150,000 nodes ran past a minute, growing with the square of its depth,
// and so did a transform file of 150,000 frames). A deep chain would overflow the stack if any
// step recursed; the times are the benchmark's business (the note reports them), this checks
// that the scene and the animation are what the files say.
TEST(HostileInput, ADeepChainOfNodesAndALongTransformFileLoadAsTheySay) {
    const int depth = kSanitized ? 20000 : 100000;  // a recursive step would need megabytes of stack
    nlohmann::json doc = nlohmann::json::parse(readFileBytes(dataDir() / "good" / "base.gltf"));
    nlohmann::json& nodes = doc["nodes"];
    const nlohmann::json floor = nodes[0];
    // nodes[0] becomes the root of the chain; each link moves 1e-6 up; the floor hangs from the last.
    nodes[0] = {{"name", "Link0"}, {"translation", {0, 1e-6, 0}}, {"children", {2}}};
    for (int i = 1; i < depth; ++i)
        nodes.push_back({{"name", "Link" + std::to_string(i)}, {"translation", {0, 1e-6, 0}}, {"children", {i + 2}}});
    nodes.push_back(floor);
    const fs::path dir = testScratchDir("hostile-chain");
    const fs::path scenePath = dir / "chain.gltf";
    std::ofstream(scenePath) << doc.dump();
    // Copy the buffers the file names beside it.
    for (const auto& buffer : doc["buffers"])
        if (buffer.contains("uri") && buffer["uri"].get<std::string>().rfind("data:", 0) != 0)
            fs::copy_file(dataDir() / "good" / buffer["uri"].get<std::string>(), dir / buffer["uri"].get<std::string>(),
                          fs::copy_options::overwrite_existing);
    Warnings warnings;
    const Scene scene = loadGltfScene(scenePath.string(), warnings);
    ASSERT_EQ(scene.nodes.size(), size_t(depth) + 2);
    ASSERT_EQ(scene.positions.size(), 4u);
    // Every link lifted the floor by 1e-6: the world transform composed all of them.
    const Vec3d corner = Vec3d(scene.positions[0]) + scene.worldOrigin;
    EXPECT_NEAR(corner.y, depth * 1e-6, 1e-9 * depth);

    // A transform file keying the floor at every frame, by its name; every frame holds its own key.
    const int frames = kSanitized ? 10000 : 50000;
    nlohmann::json animation = {{"format", "qsgi-animation"}, {"version", 1}, {"frames", nlohmann::json::array()}};
    for (int f = 0; f < frames; ++f)
        animation["frames"].push_back({{"frame", f}, {"nodes", {{"Floor", {{"translation", {0, 1e-3 * (f % 7), 0}}}}}}});
    const fs::path animationPath = dir / "long.json";
    std::ofstream(animationPath) << animation.dump();
    const Scene base = loadGltfScene((dataDir() / "good" / "base.gltf").string(), warnings);
    const Animation a = Animation::fromTransformFile(animationPath.string(), base);
    ASSERT_EQ(a.lastFrame(), frames - 1);
    ASSERT_EQ(a.movedNodes(), std::vector<int>{0});
    for (int f : {0, 1, 6, 7, frames / 2, frames - 1})
        EXPECT_DOUBLE_EQ(a.localsAt(f)[0].at(1, 3), 1e-3 * (f % 7)) << "frame " << f;
}

// A glTF animation without channels loads (with a warning: glTF requires one) and has frame 0
// alone; the Animation says which animation it is and why it ends there, for the message about
// frames beyond it. One with keys says where they end.
TEST(HostileInput, AGltfAnimationWithoutChannelsNamesItselfAndWhyItHasOneFrame) {
    nlohmann::json doc = nlohmann::json::parse(readFileBytes(dataDir() / "good" / "base.gltf"));
    doc["animations"] = {{{"name", "Idle"}, {"channels", nlohmann::json::array()}, {"samplers", nlohmann::json::array()}}};
    const fs::path dir = testScratchDir("hostile-animation-without-channels");
    std::ofstream(dir / "idle.gltf") << doc.dump();
    Warnings warnings;
    Scene scene;
    ASSERT_NO_THROW(scene = loadGltfScene((dir / "idle.gltf").string(), warnings));
    bool warned = false;
    for (const std::string& w : warnings.messages) warned = warned || w.find("animations[0] has no channels") != std::string::npos;
    EXPECT_TRUE(warned);
    for (int index : {0, -1}) {
        const Animation idle = Animation::fromGltf(scene, index, 24, "idle.gltf (--animation gltf)");
        EXPECT_EQ(idle.lastFrame(), 0);
        EXPECT_TRUE(idle.hasNoChannels());
        EXPECT_EQ(idle.name(), "glTF animation 0 'Idle'");
        EXPECT_EQ(idle.lastFrameReason(), "glTF animation 0 'Idle' has no channels to play, so it moves nothing and has frame 0 alone");
    }

    const Scene walker = loadGltfScene((sourceDir() / "data/walker/walker.gltf").string(), warnings);
    const Animation walk = Animation::fromGltf(walker, 0, 24, "walker.gltf (--animation gltf:0)");
    EXPECT_FALSE(walk.hasNoChannels());
    EXPECT_EQ(walk.name(), "glTF animation 0 'Walk'");
    EXPECT_EQ(walk.lastFrameReason().rfind("glTF animation 0 'Walk' has keys up to ", 0), 0u) << walk.lastFrameReason();
    EXPECT_NE(walk.lastFrameReason().find(": frames 0 to " + std::to_string(walk.lastFrame()) + " at 24 fps"), std::string::npos)
        << walk.lastFrameReason();
    const Animation file = Animation::fromTransformFile((dataDir() / "bad/animation/moves_the_light.json").string(),
                                                       loadGltfScene((dataDir() / "good" / "base.gltf").string(), warnings));
    EXPECT_EQ(file.lastFrameReason(), "transform file " + (dataDir() / "bad/animation/moves_the_light.json").string() +
                                          " lists frames up to 1");
    EXPECT_EQ(Animation::still(walker).lastFrameReason(), "");
}

namespace {

// Every line a run printed is qsgi's own ("qsgi: …"): no library wrote to the terminal.
void expectOnlyQsgisLines(const std::string& output) {
    std::istringstream lines(output);
    for (std::string line; std::getline(lines, line);)
        EXPECT_EQ(line.rfind("qsgi: ", 0), 0u) << "a line qsgi did not write: " << line;
}

// Whether some warning names `place` and says `words`.
bool warned(const Warnings& warnings, const std::string& place, const std::string& words) {
    for (const std::string& w : warnings.messages)
        if (w.find(place) != std::string::npos && w.find(words) != std::string::npos) return true;
    return false;
}

}  // namespace

// `qsgi compare` reads two PLYs it did not write: a header's counts are checked against the file's
// size before anything is allocated for them (both arguments), and what is no file is named so.
TEST(HostileInput, ComparedPlysThatAreNoFilesOrClaimMoreThanTheyHoldAreRefusedByName) {
    const std::string good = (dataDir() / "good" / "frame.ply").string();
    const fs::path dir = testScratchDir("hostile-ply");
    const fs::path pipe = dir / "pipe.ply";
    fs::remove(pipe);
    ASSERT_EQ(mkfifo(pipe.c_str(), 0600), 0);
    const std::string huge = (dataDir() / "bad/ply/vertex_count_huge.ply").string();
    const std::vector<std::pair<std::string, std::string>> cases = {
        {good + " " + huge, huge + ": header, element vertex (line 3): declares 200000000 vertices"},
        {dir.string() + " " + good, dir.string() + ": is a directory, not a PLY file"},
        {good + " " + pipe.string(), pipe.string() + ": is a named pipe, not a regular file"},
    };
    for (const auto& [args, message] : cases) {
        // Under 1 GiB of address space: a count believed would fail to allocate, not exit 2.
        const CommandResult r = runCommand((kSanitized ? std::string() : "ulimit -v 1048576 && ") + QSGI_CLI +
                                           " compare " + args);
        SCOPED_TRACE(args + "\n" + r.output);
        EXPECT_EQ(r.exitCode, 2);
        EXPECT_EQ(r.output.rfind("qsgi: error: " + message, 0), 0u);
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1);
    }
}

// A texture whose uri names no readable file (a directory, a pipe, a device, a file past 2 GiB,
// nothing) leaves its material's factor with one warning naming the image and the uri; tinygltf
// never opens such a path (a pipe would block it, a directory made it allocate 2^63 bytes). An
// image nothing decodes is an unused object: a warning, refused under --strict.
TEST(HostileInput, TextureUrisNamingNoReadableFileLeaveTheFactorWithAWarningNamingTheUri) {
    const fs::path dir = testScratchDir("hostile-texture-uri");
    fs::create_directories(dir / "folder.png");
    fs::remove(dir / "pipe.png");
    ASSERT_EQ(mkfifo((dir / "pipe.png").c_str(), 0600), 0);
    { std::ofstream(dir / "huge.png") << "x"; }
    fs::resize_file(dir / "huge.png", uint64_t(3) << 30);  // sparse: nothing is written, or read
    std::string device = "dev/null";
    for (int up = 0; up < 64; ++up) device = "../" + device;  // past the root stays at the root
    const std::vector<std::pair<std::string, std::string>> images = {
        {"folder.png", "names a directory, not a file"},
        {"pipe.png", "names a named pipe, not a regular file"},
        {device, "names a device, not a regular file"},
        {"huge.png", "names a file of 3221225472 bytes, beyond the 2 GiB qsgi reads for an image"},
        {"missing.png", "names no file (looked beside the glTF file)"},
        {"folder.png", "names a directory, not a file"},  // images[5]: no material decodes it
    };
    nlohmann::json doc = nlohmann::json::parse(readFileBytes(dataDir() / "good" / "texture_data_uri.gltf"));
    doc["images"] = nlohmann::json::array();
    doc["textures"] = nlohmann::json::array();
    doc["materials"] = nlohmann::json::array();
    for (size_t i = 0; i < images.size(); ++i) {
        doc["images"].push_back({{"uri", images[i].first}});
        doc["textures"].push_back({{"source", i}});
        if (i + 1 < images.size())
            doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", i}}}, {"baseColorFactor", {0.5, 0.25, 1, 1}}}}});
    }
    const fs::path file = dir / "scene.gltf";
    std::ofstream(file) << doc.dump();

    Warnings warnings;
    Scene scene;
    ASSERT_NO_THROW(scene = loadGltfScene(file.string(), warnings));
    for (size_t i = 0; i + 1 < images.size(); ++i) {
        SCOPED_TRACE(images[i].first);
        EXPECT_EQ(scene.materials[i].albedo, Vec3f(0.5f, 0.25f, 1.0f));
        const std::string image = "images[" + std::to_string(i) + "].uri '" + images[i].first + "' ";
        EXPECT_TRUE(warned(warnings, "materials[" + std::to_string(i) + "].pbrMetallicRoughness.baseColorTexture: " + image,
                           images[i].second + "; using baseColorFactor alone"));
    }
    EXPECT_TRUE(warned(warnings, "images[5].uri: 'folder.png' names a directory, not a file",
                       "(images[5] is not in the rendered scene, so it is ignored)"));
    for (const std::string& w : warnings.messages) EXPECT_EQ(w.find("File read error"), std::string::npos) << w;

    const CommandResult quiet = runQsgi("render " + file.string() + " --photons 1000 --quiet --out " + (dir / "out").string());
    EXPECT_EQ(quiet.exitCode, 0) << quiet.output;
    EXPECT_EQ(quiet.output, "") << "--quiet prints errors only";
    const CommandResult strict = runQsgi("inspect --strict " + file.string());
    EXPECT_EQ(strict.exitCode, 2) << strict.output;
    EXPECT_NE(strict.output.find("images[5].uri: 'folder.png' names a directory, not a file"), std::string::npos) << strict.output;
    EXPECT_EQ(std::count(strict.output.begin(), strict.output.end(), '\n'), 1) << strict.output;
}

// PNGs libpng refuses (tests/data/good/texture_png_hostile.gltf: a header PNG forbids, a CRC,
// zlib or filter error, data that ends early) leave each material's factor with a warning in
// qsgi's words, and no library prints a line, with --quiet or without.
TEST(HostileInput, HostilePngTexturesWarnInQsgisWordsAndNoLibraryPrints) {
    const fs::path file = dataDir() / "good" / "texture_png_hostile.gltf";
    Warnings warnings;
    Scene scene;
    ASSERT_NO_THROW(scene = loadGltfScene(file.string(), warnings));
    size_t rows = 0;
    std::ifstream table(dataDir() / "good" / "texture_png_hostile.tsv");
    for (std::string line; std::getline(table, line);) {
        if (line.empty() || line[0] == '#') continue;
        const int m = std::stoi(line.substr(0, line.find('\t')));
        const std::string words = line.substr(line.find('\t') + 1);
        SCOPED_TRACE("materials[" + std::to_string(m) + "]: " + words);
        EXPECT_EQ(scene.materials[size_t(m)].albedo, Vec3f(0.5f, 0.25f, 1.0f));
        EXPECT_TRUE(warned(warnings, "materials[" + std::to_string(m) + "].pbrMetallicRoughness.baseColorTexture: images[" +
                                         std::to_string(m) + "] ",
                           words));
        ++rows;
    }
    EXPECT_GE(rows, 12u);

    const fs::path dir = testScratchDir("hostile-png");
    const CommandResult quiet = runQsgi("render " + file.string() + " --photons 1000 --quiet --out " + (dir / "quiet").string());
    EXPECT_EQ(quiet.exitCode, 0) << quiet.output;
    EXPECT_EQ(quiet.output, "") << "--quiet prints errors only";
    const CommandResult loud = runQsgi("render " + file.string() + " --photons 1000 --out " + (dir / "loud").string());
    EXPECT_EQ(loud.exitCode, 0) << loud.output;
    EXPECT_NE(loud.output.find("qsgi: warning: "), std::string::npos) << loud.output;
    expectOnlyQsgisLines(loud.output);
}

// KHR_lights_punctual's range is positive where given: refused in a light the render uses
// (bad/gltf/light_range_*.gltf), a warning in one no node of the scene uses, refused by --strict.
TEST(HostileInput, ALightRangeNotPositiveInALightNothingUsesWarnsAndStrictRefusesIt) {
    nlohmann::json doc = nlohmann::json::parse(readFileBytes(dataDir() / "good" / "base.gltf"));
    doc["extensions"]["KHR_lights_punctual"]["lights"].push_back({{"type", "point"}, {"intensity", 1}, {"range", 0}});
    const fs::path file = fs::path(testScratchDir("hostile-light-range")) / "unused.gltf";
    std::ofstream(file) << doc.dump();
    Warnings warnings;
    ASSERT_NO_THROW(loadGltfScene(file.string(), warnings));
    EXPECT_TRUE(warned(warnings, "KHR_lights_punctual.lights[1].range: is 0",
                       "(KHR_lights_punctual.lights[1] is not in the rendered scene, so it is ignored)"));
    GltfReadOptions strict;
    strict.strict = true;
    try {
        loadGltfScene(file.string(), warnings, strict);
        ADD_FAILURE() << "--strict should refuse it";
    } catch (const InputError& e) {
        EXPECT_EQ(e.place(), "KHR_lights_punctual.lights[1].range");
    }
}
