// Helpers shared by the tests: paths, scratch folders, scenes built in code, and running the CLI.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "estimate/estimator.h"
#include "estimate/vertex_starts.h"
#include "scene/scene.h"
#include "trace/photon_numbers.h"
#include "trace/ray_cache.h"
#include "trace/scene_bvh.h"

// Whether this build runs under AddressSanitizer (scripts/test-sanitizers.sh), where every
// instruction costs several times more. There the question is memory safety, not statistics: a
// test whose property holds at any size (indexed == brute force, incremental == full) may check
// it on fewer cases or a smaller instance, and says so where it does.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

// For tests whose subject is not the light (files, folders, resuming, the CLI): the second pass
// stays on (exact direct light and a gather, the defaults' kind of render), at a sixteenth of the
// defaults' gather rays and direct samples, which a frame of data/cornell otherwise spends most of
// its time on.
inline constexpr const char* kCheapSecondPass = " --gather 16 --direct-samples 4";

std::filesystem::path sourceDir();  // the repository root
std::filesystem::path sharedDir();  // ../shared beside the repository (may be absent)
std::string testScratchDir(const std::string& name);
// A scene of the reference tests (tests/reference_accuracy_test.cpp, tests/gather_accuracy_test.cpp)
// by its path under the repository, lit as its reference was rendered: a scene named *_sky.gltf
// has no light of its own and gets the uniform sky of radiance 1 its reference was made under
// (scripts/reference.py --sky 1,1,1), as --sky 1,1,1 gives it.
qsgi::Scene loadReferenceScene(const std::string& relativePath);

struct CommandResult {
    int exitCode;
    std::string output;  // stdout and stderr together
};
CommandResult runQsgi(const std::string& arguments);     // the qsgi executable with these arguments
CommandResult runCommand(const std::string& commandLine);  // any shell command line
std::string readFileBytes(const std::filesystem::path& path);  // "" if unreadable
// The names of an output folder's frame_* entries, and the frames its timing.json lists, in order.
std::set<std::string> frameFiles(const std::filesystem::path& dir);
std::vector<int> loggedFrames(const std::filesystem::path& dir);

// Every field of the two segments has the same bits.
bool sameBits(const qsgi::Segment& a, const qsgi::Segment& b);
// The two caches hold the same paths and, decoded, segments with the same bits in the same order.
bool sameSegments(const qsgi::RayCache& a, const qsgi::RayCache& b);

// An estimator and its boundary rule, named for test messages.
struct NamedEstimator {
    const char* name;
    qsgi::EstimatorKind kind;
    qsgi::DetpBoundary rule;
    qsgi::EstimatorSettings settings(float radius, int k = 50) const;
};

// Every photon of the scene traced once (max 32 bounces), as a render's first frame does; aimed
// (issue 12) unless `aim` is false; with the default sampler unless another is given.
qsgi::RayCache traceScene(const qsgi::Scene& scene, uint64_t photons, uint64_t seed, bool aim = true,
                          const qsgi::PhotonSampling& sampling = {});
// Density estimation of the scene's current pose with these settings (disc regions computed here).
qsgi::VertexRadiosity estimateWith(const qsgi::Scene& scene, const qsgi::RayCache& cache,
                                   const qsgi::EstimatorSettings& settings);

// Scenes built in code, with one instance per mesh (built in test_support.cpp).
namespace testscenes {
qsgi::Scene closedSphere(float radius, int subdivisions, qsgi::Vec3f albedo, bool inwardNormals = true);
qsgi::Scene plane(float halfSize, int cells, qsgi::Vec3f albedo);
// A closed box [-1,1]^3 with coloured walls facing inward.
qsgi::Scene closedBox(int cells);
// A 4x4 m floor (y = 0; 2·floorHalf a side when given) with a 0.6 m cube on it: the cube's
// convex edges make silhouettes.
qsgi::Scene boxOnFloor(int floorCells, int cubeCells, qsgi::Vec3f albedo, float floorHalf = 2.0f);
// A floor y = 0 (x, z in [-1, 1], `floorCells` per side, its vertices first) with a closed slab
// standing on it: [−half, half]² and `height` high (a rug, when low).
qsgi::Scene slabOnFloor(int floorCells, float half, float height, qsgi::Vec3f albedo);
// A floor y = 0 (x, z in [−floorHalf, floorHalf], `floorCells` per side, its vertices first) with a
// block standing on it: [−blockHalf, blockHalf]², `height` high, `blockCells` per face, its sides and
// top facing out and no bottom (closed against the floor).
qsgi::Scene blockOnFloor(int floorCells, float floorHalf, float blockHalf, float height, int blockCells, qsgi::Vec3f albedo);
// An inside corner: floor y = 0 (x in [-1,1], z in [0,depth]) and wall z = 0 (x in [-1,1], y in
// [0,depth]), `cells` per 2 m in every direction (cells·depth/2 across the depth).
qsgi::Scene corner(int cells, qsgi::Vec3f albedo, float depth = 2.0f);
// plane(halfSize, cells, albedo) without its inside: only the cells within `borderCells` of its
// edge (one welded mesh, y = 0, facing +y), its vertices numbered in the order the cells need them.
qsgi::Scene squareFrame(float halfSize, int cells, int borderCells, qsgi::Vec3f albedo);
// A floor y = 0 (x, z in [-1, 1]) with a square opaque plate (half size `half`, zero thickness,
// facing up) `gap` above it.
qsgi::Scene plateOverFloor(int floorCells, float half, float gap, qsgi::Vec3f albedo);
// A floor y = 0 (x, z in [-1, 1]) cut by a zero-thickness wall z = 0 (x in [-1, 1], y in [0, 1])
// facing +z.
qsgi::Scene partition(int cells, qsgi::Vec3f albedo);
// An L-shaped sheet: floor y = 0 (z in [0, 1]) and wall z = 0 (y in [0, 1]), x in [-1, 1]. welded:
// one mesh whose crease row is shared and whose normals are area-weighted (the crease vertices'
// normals are 45° from both faces); otherwise the crease row is duplicated, each side with its
// face normal. Both have the same triangles in the same order. farQuad > 0 adds, after the sheet,
// a black 1 m quad facing +y that far off along +x (issue 56: it only enlarges the scene).
qsgi::Scene creasedSheet(int cells, bool welded, qsgi::Vec3f albedo, float farQuad = 0);
// A square plate y = 0 (half size `half`, `cells` per side, facing up) and, `offset` along x
// from its centre, a sliver y = 0 (`width` along x, 1 along z, 10 cells, facing up).
qsgi::Scene plateAndSliver(float half, int cells, float width, float offset, qsgi::Vec3f albedo);
// A floor of tiles x tiles square tiles (each its own instance of `cells` x `cells` cells, 4 mm
// apart, welded to its neighbours by position only), as scripts/make_bench_scenes.py's dense
// floor, placed by `placement` (a tilt makes every height rounding noise), with a 0.1 m box of
// 8 cells a face standing on it off-centre.
qsgi::Scene tiledFloor(int tiles, int cells, const qsgi::Transform& placement, qsgi::Vec3f albedo);
// boxOnFloor(16, 3, albedo) ("Floor", "Cube") and a static square tube ("Tube") along x, open at
// both ends, doubleSided (its back sides not yet made): x in [0.5, 3.5], y in [0.05, 0.85], z in
// [−0.4, 0.4], four walls facing out, 20 x 6 cells each. The cube slid by +0.9 along x stands
// inside it, through its bottom wall.
qsgi::Scene cubeBesideTube(qsgi::Vec3f albedo);
void addPointLight(qsgi::Scene& s, qsgi::Vec3f position, qsgi::Vec3f intensity);
// Materials as an asset gives them (issue 57), for scenes built in code: `material` reading a
// texture of `width` x `height` RGBA8 pixels (`rgba`, top row first) through TEXCOORD_0, added
// to the scene; returns its index.
uint32_t addTexturedMaterial(qsgi::Scene& s, qsgi::Material material, int width, int height, std::vector<uint8_t> rgba,
                             bool nearest = true);
// Gives instance `instance` material `material`, and TEXCOORD_0 projected from its rest-pose world
// positions: s = (p[axisS] − origin[axisS]) / size, t = (p[axisT] − origin[axisT]) / size.
void paintInstance(qsgi::Scene& s, size_t instance, uint32_t material, int axisS, int axisT, qsgi::Vec3f origin, float size);
// Writes a small glTF (a quad; emissive if lit) with an embedded buffer.
void writeQuadGltf(const std::string& path, bool lit);

// Assembles a glTF document in memory for tests: the JSON is edited directly, binary data goes
// through accessor(), and write() embeds the buffer as a base64 data URI.
struct GltfWriter {
    nlohmann::json doc = {{"asset", {{"version", "2.0"}}}, {"scene", 0}};
    std::string bin;
    // An accessor over `values` (float, or unsigned short if indices) of glTF type `type`
    // ("SCALAR", "VEC3", …); min and max are set (glTF requires them for POSITION and inputs).
    int accessor(const std::vector<float>& values, const std::string& type);
    int indices(const std::vector<uint16_t>& values);
    // Appends a node and returns its index.
    int node(nlohmann::json node);
    void write(const std::string& path) const;
};
}  // namespace testscenes

// Scenes of the direct-light and final-gather tests (tests/direct_light_test.cpp,
// tests/final_gather_test.cpp).
namespace testscenes {
// A floor y = 0 (x, z in [-1, 1], `cells` per side, facing up) under an emissive rectangle of two
// triangles (material emission `emission`, the floor's albedo) centred at `centre`, parallel to
// the floor, half sizes `halfX` and `halfZ`, its front (CCW) side facing down.
qsgi::Scene floorUnderEmitter(int cells, qsgi::Vec3f centre, float halfX, float halfZ, qsgi::Vec3f emission,
                              qsgi::Vec3f albedo);
// Many lights (issue 58): a 4 m floor (`cells` per side) with three 0.5 m blocks on it, under
// `lamps` small emissive squares facing down at random heights and sizes, and `lights` point and
// spot lights (every third a spot aimed down) at random places, some under the floor; all drawn
// from `seed`.
qsgi::Scene lampsOverBlocks(int cells, int lamps, int lights, uint64_t seed);
// A plate y = 0 (half size `plateHalf`, facing up) under a single-sided sheet y = `gap` (half size
// `sheetHalf`), both centred on the y axis. sheetFacesUp: the sheet's front (winding and vertex
// normals) faces +y, away from the plate, else −y, toward it. The plate is instance 0, the sheet
// instance 1.
qsgi::Scene plateUnderSheet(float plateHalf, int plateCells, float sheetHalf, int sheetCells, float gap,
                            bool sheetFacesUp, qsgi::Vec3f albedo);
}  // namespace testscenes

// What the second pass's tests read (tests/direct_light_test.cpp, tests/final_gather_test.cpp): the
// scene's BVH and the rays' start points as the second pass reads them.
struct SecondPassRig {
    qsgi::EmbreeDevice device;
    qsgi::SceneBvh bvh;
    qsgi::VertexStarts starts;
    explicit SecondPassRig(const qsgi::Scene& scene) : bvh(device, scene) { starts.computeAll(scene, bvh); }
};
