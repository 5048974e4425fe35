#include "test_support.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <sstream>

#include <unistd.h>

#include "scene/gltf_loader.h"
#include "trace/photon_tracer.h"

namespace fs = std::filesystem;
using namespace qsgi;

fs::path sourceDir() { return fs::path(QSGI_SOURCE_DIR); }
fs::path sharedDir() { return sourceDir().parent_path() / "shared"; }

Scene loadReferenceScene(const std::string& relativePath) {
    Warnings w;
    Scene scene = loadGltfScene((sourceDir() / relativePath).string(), w);
    const std::string suffix = "_sky.gltf";
    if (relativePath.size() > suffix.size() && relativePath.compare(relativePath.size() - suffix.size(), suffix.size(), suffix) == 0)
        scene.environment = std::make_shared<const EnvironmentLight>(EnvironmentLight::uniform(Vec3f(1.0f)));
    return scene;
}

namespace {
// Every test process writes under a folder of its own, so that two test runs at once (the release
// and sanitizer builds, or a developer's run beside CI) never share a scratch folder; the folder
// goes when the process ends.
struct ProcessScratchRoot {
    fs::path path = fs::temp_directory_path() / ("qsgi_test_" + std::to_string(::getpid()));
    ~ProcessScratchRoot() {
        std::error_code ignored;
        fs::remove_all(path, ignored);
    }
};
}  // namespace

std::string testScratchDir(const std::string& name) {
    static ProcessScratchRoot root;
    auto p = root.path / name;
    fs::remove_all(p);
    fs::create_directories(p);
    return p.string();
}

std::set<std::string> frameFiles(const std::filesystem::path& dir) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().rfind("frame_", 0) == 0) names.insert(e.path().filename().string());
    return names;
}

std::vector<int> loggedFrames(const std::filesystem::path& dir) {
    std::vector<int> frames;
    const nlohmann::json log = nlohmann::json::parse(readFileBytes(dir / "timing.json"));
    for (const auto& f : log["frames"]) frames.push_back(f["frame"]);
    return frames;
}

CommandResult runQsgi(const std::string& arguments) { return runCommand(std::string(QSGI_CLI) + " " + arguments); }

CommandResult runCommand(const std::string& commandLine) {
    const std::string command = commandLine + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    CommandResult r{-1, ""};
    if (!pipe) return r;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
    const int status = pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

std::string readFileBytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

EstimatorSettings NamedEstimator::settings(float radius, int k) const {
    EstimatorSettings s;
    s.kind = kind;
    s.detp.boundary = rule;
    s.radius = radius;
    s.photonMap.k = k;
    return s;
}

RayCache traceScene(const Scene& scene, uint64_t photons, uint64_t seed, bool aim, const PhotonSampling& sampling) {
    EmbreeDevice device;
    const SceneBvh bvh(device, scene);
    // Aimed as a render aims (issue 12), at 10 % of the diagonal beside the geometry: more than
    // any DETP radius the tests estimate these photons with.
    const EmissionAim aiming{aim, 0.1f * scene.animationBounds.extent()};
    return PhotonTracer(scene, bvh, TraceSettings{photons, seed, 32, aiming, sampling}).traceAll();
}

VertexRadiosity estimateWith(const Scene& scene, const RayCache& cache, const EstimatorSettings& settings) {
    EmbreeDevice device;
    const SceneBvh bvh(device, scene);
    return estimateVertexRadiosity(scene, bvh, cache, settings, device);
}

namespace testscenes {

namespace {
uint32_t addMaterial(Scene& s, Vec3f albedo, Vec3f emission = Vec3f(0.0f)) {
    s.materials.push_back(Material{"m" + std::to_string(s.materials.size()), albedo, emission});
    return uint32_t(s.materials.size() - 1);
}

// Quad grid from corner spanning u (cellsU cells) and v (cellsV cells); front (CCW) side faces
// cross(u, v). With `keep`, only the cells (i, j) it accepts, and only their vertices.
void addGrid(Scene& s, int node, Vec3f corner, Vec3f u, Vec3f v, int cellsU, int cellsV, uint32_t material,
             const std::function<bool(int, int)>& keep = {}) {
    std::vector<Vec3f> p, n;
    std::vector<uint32_t> idx;
    const Vec3f normal = normalize(cross(u, v));
    const int row = cellsU + 1;
    std::vector<uint32_t> index(size_t(row) * size_t(cellsV + 1), UINT32_MAX);
    auto vertex = [&](int i, int j) {
        uint32_t& k = index[size_t(j) * size_t(row) + size_t(i)];
        if (k == UINT32_MAX) {
            k = uint32_t(p.size());
            p.push_back(corner + u * (float(i) / cellsU) + v * (float(j) / cellsV));
            n.push_back(normal);
        }
        return k;
    };
    if (!keep)  // every vertex, in rows, as the grids always were numbered
        for (int j = 0; j <= cellsV; ++j)
            for (int i = 0; i <= cellsU; ++i) vertex(i, j);
    for (int j = 0; j < cellsV; ++j)
        for (int i = 0; i < cellsU; ++i) {
            if (keep && !keep(i, j)) continue;
            const uint32_t a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1), d = vertex(i, j + 1);
            idx.insert(idx.end(), {a, b, c, a, c, d});
        }
    s.addInstance(node, std::move(p), std::move(n), idx, material);
}

void addGrid(Scene& s, int node, Vec3f corner, Vec3f u, Vec3f v, int cells, uint32_t material) {
    addGrid(s, node, corner, u, v, cells, cells, material);
}

// A box standing on y = 0 over [−half, half]² and `height` high: its four sides and top, facing
// out (the bottom, on the floor, left out), `cells` per face.
void addBoxOnFloor(Scene& s, int node, float half, float height, int cells, uint32_t material) {
    const float h = half;
    addGrid(s, node, {-h, 0, h}, {2 * h, 0, 0}, {0, height, 0}, cells, material);           // +z
    addGrid(s, node, {h, 0, -h}, {-2 * h, 0, 0}, {0, height, 0}, cells, material);          // -z
    addGrid(s, node, {h, 0, h}, {0, 0, -2 * h}, {0, height, 0}, cells, material);           // +x
    addGrid(s, node, {-h, 0, -h}, {0, 0, 2 * h}, {0, height, 0}, cells, material);          // -x
    addGrid(s, node, {-h, height, h}, {2 * h, 0, 0}, {0, 0, -2 * h}, cells, material);      // top
}
}  // namespace

uint32_t addTexturedMaterial(Scene& s, Material material, int width, int height, std::vector<uint8_t> rgba, bool nearest) {
    auto image = std::make_shared<TextureImage>();
    image->width = uint32_t(width);
    image->height = uint32_t(height);
    image->rgba = std::move(rgba);
    auto textures = std::make_shared<TextureSet>(s.textures ? *s.textures : TextureSet());
    Texture texture;
    texture.image = std::move(image);
    texture.nearest = nearest;
    textures->push_back(texture);
    material.baseColour.texture = int(textures->size() - 1);
    material.baseColour.texCoord = 0;
    s.textures = std::move(textures);
    s.materials.push_back(std::move(material));
    return uint32_t(s.materials.size() - 1);
}

void paintInstance(Scene& s, size_t instance, uint32_t material, int axisS, int axisT, Vec3f origin, float size) {
    const MeshInstance& inst = s.instances[instance];
    if (s.vertexTexCoords.empty()) s.vertexTexCoords.resize(1);
    s.vertexTexCoords[0].resize(s.vertexCount());
    for (uint32_t v = inst.firstVertex; v < inst.firstVertex + inst.vertexCount; ++v) {
        s.vertexMaterial[v] = material;
        const Vec3f& p = s.positions[v];
        s.vertexTexCoords[0][v] = {(p[axisS] - origin[axisS]) / size, (p[axisT] - origin[axisT]) / size};
    }
    for (uint32_t t = inst.firstTriangle; t < inst.firstTriangle + inst.triangleCount; ++t) s.triangleMaterial[t] = material;
}

Scene closedSphere(float radius, int subdivisions, Vec3f albedo, bool inwardNormals) {
    // Icosphere: near-uniform triangles, so impact-count noise is alike everywhere.
    const float t = (1 + std::sqrt(5.0f)) / 2;
    std::vector<Vec3f> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    std::vector<uint32_t> idx = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2,
                                 10, 7, 6, 7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5,
                                 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
    for (auto& q : p) q = normalize(q);
    for (int level = 0; level < subdivisions; ++level) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            p.push_back(normalize(p[a] + p[b]));
            return mid[key] = uint32_t(p.size() - 1);
        };
        std::vector<uint32_t> next;
        for (size_t i = 0; i < idx.size(); i += 3) {
            const uint32_t a = idx[i], b = idx[i + 1], c = idx[i + 2];
            const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
        }
        idx.swap(next);
    }
    std::vector<Vec3f> n(p.size());
    for (size_t i = 0; i < p.size(); ++i) {
        n[i] = inwardNormals ? -p[i] : p[i];
        p[i] = p[i] * radius;
    }
    if (inwardNormals)
        for (size_t i = 0; i < idx.size(); i += 3) std::swap(idx[i + 1], idx[i + 2]);
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    s.addInstance(s.addNode("Sphere", Transform()), std::move(p), std::move(n), idx, m);
    s.finalize();
    return s;
}

Scene plane(float halfSize, int cells, Vec3f albedo) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    // y = 0, facing +y.
    addGrid(s, s.addNode("Plane", Transform()), {-halfSize, 0, halfSize}, {2 * halfSize, 0, 0}, {0, 0, -2 * halfSize}, cells, m);
    s.finalize();
    return s;
}

Scene tiledFloor(int tiles, int cells, const Transform& placement, Vec3f albedo) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    const int floor = s.addNode("Floor", placement);
    const float tile = 0.004f * float(cells), half = 0.5f * tile * float(tiles);
    for (int j = 0; j < tiles; ++j)
        for (int i = 0; i < tiles; ++i) {
            const int node = s.addNode("Tile" + std::to_string(i) + "_" + std::to_string(j),
                                       Transform::fromTRS(Vec3d(-half + tile * float(i), 0, -half + tile * float(j)), {0, 0, 0, 1},
                                                          Vec3d(1.0)),
                                       floor);
            addGrid(s, node, {0, 0, tile}, {tile, 0, 0}, {0, 0, -tile}, cells, m);
        }
    addBoxOnFloor(s, s.addNode("Box", Transform::fromTRS(Vec3d(0.3 * half, 0, 0.2 * half), {0, 0, 0, 1}, Vec3d(1.0)), floor),
                  0.05f, 0.1f, 8, m);
    s.finalize();
    return s;
}

Scene plateAndSliver(float half, int cells, float width, float offset, Vec3f albedo) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    addGrid(s, s.addNode("Plate", Transform()), {-half, 0, half}, {2 * half, 0, 0}, {0, 0, -2 * half}, cells, m);
    // Ten pieces along its length (addGrid's grids are square in cells), one cell each.
    for (int k = 0; k < 10; ++k) {
        const float z = 0.5f - 0.1f * float(k);
        addGrid(s, s.addNode("Sliver" + std::to_string(k), Transform()), {offset - 0.5f * width, 0, z}, {width, 0, 0},
                {0, 0, -0.1f}, 1, m);
    }
    s.finalize();
    return s;
}

Scene closedBox(int cells) {
    Scene s;
    const int node = s.addNode("Box", Transform());
    const uint32_t white = addMaterial(s, {0.725f, 0.71f, 0.68f}), red = addMaterial(s, {0.63f, 0.065f, 0.05f}),
                   green = addMaterial(s, {0.14f, 0.45f, 0.091f});
    addGrid(s, node, {-1, -1, 1}, {2, 0, 0}, {0, 0, -2}, cells, white);   // floor, +y
    addGrid(s, node, {-1, 1, -1}, {2, 0, 0}, {0, 0, 2}, cells, white);    // ceiling, -y
    addGrid(s, node, {-1, -1, -1}, {2, 0, 0}, {0, 2, 0}, cells, white);   // back, +z
    addGrid(s, node, {1, -1, 1}, {-2, 0, 0}, {0, 2, 0}, cells, white);    // front, -z
    addGrid(s, node, {-1, -1, 1}, {0, 0, -2}, {0, 2, 0}, cells, red);     // left, +x
    addGrid(s, node, {1, -1, -1}, {0, 0, 2}, {0, 2, 0}, cells, green);    // right, -x
    s.finalize();
    return s;
}

Scene boxOnFloor(int floorCells, int cubeCells, Vec3f albedo, float floorHalf) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    const int floor = s.addNode("Floor", Transform());
    addGrid(s, floor, {-floorHalf, 0, floorHalf}, {2 * floorHalf, 0, 0}, {0, 0, -2 * floorHalf}, floorCells, m);
    const float h = 0.3f;
    addBoxOnFloor(s, s.addNode("Cube", Transform()), h, 2 * h, cubeCells, m);
    s.finalize();
    return s;
}

Scene cubeBesideTube(Vec3f albedo) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    Material tube("tube", albedo);
    tube.doubleSided = true;
    s.materials.push_back(tube);
    const uint32_t t = uint32_t(s.materials.size() - 1);
    addGrid(s, s.addNode("Floor", Transform()), {-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 16, m);
    addBoxOnFloor(s, s.addNode("Cube", Transform()), 0.3f, 0.6f, 3, m);
    const int node = s.addNode("Tube", Transform());
    addGrid(s, node, {0.5f, 0.85f, 0.4f}, {3, 0, 0}, {0, 0, -0.8f}, 20, 6, t);   // top, +y
    addGrid(s, node, {0.5f, 0.05f, -0.4f}, {3, 0, 0}, {0, 0, 0.8f}, 20, 6, t);  // bottom, −y
    addGrid(s, node, {0.5f, 0.05f, 0.4f}, {3, 0, 0}, {0, 0.8f, 0}, 20, 6, t);   // +z
    addGrid(s, node, {0.5f, 0.85f, -0.4f}, {3, 0, 0}, {0, -0.8f, 0}, 20, 6, t); // −z
    s.finalize();
    return s;
}

Scene slabOnFloor(int floorCells, float half, float height, Vec3f albedo) { return blockOnFloor(floorCells, 1.0f, half, height, 1, albedo); }

Scene blockOnFloor(int floorCells, float floorHalf, float blockHalf, float height, int blockCells, Vec3f albedo) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    addGrid(s, s.addNode("Floor", Transform()), {-floorHalf, 0, floorHalf}, {2 * floorHalf, 0, 0}, {0, 0, -2 * floorHalf}, floorCells, m);
    addBoxOnFloor(s, s.addNode("Block", Transform()), blockHalf, height, blockCells, m);
    s.finalize();
    return s;
}

Scene corner(int cells, Vec3f albedo, float depth) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    const int node = s.addNode("Corner", Transform());
    const int deep = int(std::lround(float(cells) * depth / 2));  // the same spacing as along x
    addGrid(s, node, {-1, 0, depth}, {2, 0, 0}, {0, 0, -depth}, cells, deep, m);  // floor, +y
    addGrid(s, node, {-1, 0, 0}, {2, 0, 0}, {0, depth, 0}, cells, deep, m);       // wall, +z
    s.finalize();
    return s;
}

Scene squareFrame(float halfSize, int cells, int borderCells, Vec3f albedo) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    auto inBorder = [&](int i, int j) {
        return i < borderCells || j < borderCells || i >= cells - borderCells || j >= cells - borderCells;
    };
    addGrid(s, s.addNode("Frame", Transform()), {-halfSize, 0, halfSize}, {2 * halfSize, 0, 0}, {0, 0, -2 * halfSize}, cells,
            cells, m, inBorder);
    s.finalize();
    return s;
}

Scene plateOverFloor(int floorCells, float half, float gap, Vec3f albedo) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    addGrid(s, s.addNode("Floor", Transform()), {-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, floorCells, m);
    addGrid(s, s.addNode("Plate", Transform()), {-half, gap, half}, {2 * half, 0, 0}, {0, 0, -2 * half}, 4, m);
    s.finalize();
    return s;
}

Scene partition(int cells, Vec3f albedo) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    addGrid(s, s.addNode("Floor", Transform()), {-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, cells, m);
    addGrid(s, s.addNode("Wall", Transform()), {-1, 0, 0}, {2, 0, 0}, {0, 1, 0}, cells / 2, m);
    s.finalize();
    return s;
}

Scene creasedSheet(int cells, bool welded, Vec3f albedo, float farQuad) {
    // Rows j = 0..cells run along the floor from z = 1 to the crease (z = 0); rows cells..2·cells
    // climb the wall. Columns i = 0..cells span x.
    std::vector<Vec3f> p, n;
    auto point = [&](int i, int j) {
        const float x = -1 + 2.0f * float(i) / float(cells);
        return j <= cells ? Vec3f(x, 0, 1 - float(j) / float(cells)) : Vec3f(x, float(j - cells) / float(cells), 0);
    };
    const uint32_t row = uint32_t(cells + 1);
    for (int j = 0; j <= 2 * cells; ++j)
        for (int i = 0; i <= cells; ++i) p.push_back(point(i, j));
    if (!welded)  // a second copy of the crease row, for the wall's triangles
        for (int i = 0; i <= cells; ++i) p.push_back(point(i, cells));
    const uint32_t wallCrease = uint32_t(p.size()) - row;
    auto index = [&](int i, int j, bool wallSide) {
        if (!welded && wallSide && j == cells) return wallCrease + uint32_t(i);
        return uint32_t(j) * row + uint32_t(i);
    };
    std::vector<uint32_t> idx;
    for (int j = 0; j < 2 * cells; ++j)
        for (int i = 0; i < cells; ++i) {
            const bool wallSide = j >= cells;
            const uint32_t a = index(i, j, wallSide), b = index(i + 1, j, wallSide), c = index(i + 1, j + 1, wallSide),
                           d = index(i, j + 1, wallSide);
            // Floor faces +y, wall faces +z (toward where the floor lies).
            idx.insert(idx.end(), {a, b, c, a, c, d});
        }
    if (!welded) {
        n.resize(p.size());
        for (size_t v = 0; v < p.size(); ++v) n[v] = (v < size_t(cells) * row + row) ? Vec3f(0, 1, 0) : Vec3f(0, 0, 1);
        for (int i = 0; i <= cells; ++i) n[size_t(cells) * row + size_t(i)] = Vec3f(0, 1, 0);
    }
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    s.addInstance(s.addNode("Sheet", Transform()), std::move(p), std::move(n), idx, m);
    if (farQuad > 0)
        addGrid(s, s.addNode("Far quad", Transform()), {farQuad, 0, 0.5f}, {1, 0, 0}, {0, 0, -1}, 1, addMaterial(s, Vec3f(0.0f)));
    s.finalize();
    return s;
}

void addPointLight(Scene& s, Vec3f position, Vec3f intensity) {
    PunctualLight l;
    l.name = "test point light";
    l.type = LightType::Point;
    l.position = Vec3f(Vec3d(position) - s.worldOrigin);
    l.intensity = intensity;
    s.lights.push_back(l);
}

void writeQuadGltf(const std::string& path, bool lit) {
    // Two triangles of a 1 m quad facing +y.
    GltfWriter w;
    const int positions = w.accessor({-0.5f, 0, 0.5f, 0.5f, 0, 0.5f, 0.5f, 0, -0.5f, -0.5f, 0, -0.5f}, "VEC3");
    const int indices = w.indices({0, 1, 2, 0, 2, 3});
    w.doc["scenes"] = {{{"nodes", {w.node({{"name", "Quad"}, {"mesh", 0}})}}}};
    using nlohmann::json;
    const json primitive = {{"attributes", {{"POSITION", positions}}}, {"indices", indices}, {"material", 0}};
    w.doc["meshes"] = json::array({{{"primitives", json::array({primitive})}}});
    const json material = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}}},
                           {"emissiveFactor", lit ? json({1, 1, 1}) : json({0, 0, 0})}};
    w.doc["materials"] = json::array({material});
    w.write(path);
}

namespace {
int componentsOf(const std::string& type) {
    return type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : type == "MAT4" ? 16 : 0;
}

int appendView(testscenes::GltfWriter& w, const void* data, size_t bytes) {
    while (w.bin.size() % 4) w.bin.push_back('\0');
    const size_t offset = w.bin.size();
    w.bin.append(static_cast<const char*>(data), bytes);
    w.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
    return int(w.doc["bufferViews"].size()) - 1;
}
}  // namespace

int GltfWriter::accessor(const std::vector<float>& values, const std::string& type) {
    const int n = componentsOf(type);
    const int view = appendView(*this, values.data(), values.size() * sizeof(float));
    std::vector<float> lo(size_t(n), INFINITY), hi(size_t(n), -INFINITY);
    for (size_t i = 0; i < values.size(); ++i) {
        lo[i % size_t(n)] = std::min(lo[i % size_t(n)], values[i]);
        hi[i % size_t(n)] = std::max(hi[i % size_t(n)], values[i]);
    }
    doc["accessors"].push_back({{"bufferView", view}, {"componentType", 5126}, {"count", values.size() / size_t(n)},
                                {"type", type}, {"min", lo}, {"max", hi}});
    return int(doc["accessors"].size()) - 1;
}

int GltfWriter::indices(const std::vector<uint16_t>& values) {
    const int view = appendView(*this, values.data(), values.size() * sizeof(uint16_t));
    doc["accessors"].push_back({{"bufferView", view}, {"componentType", 5123}, {"count", values.size()}, {"type", "SCALAR"}});
    return int(doc["accessors"].size()) - 1;
}

int GltfWriter::node(nlohmann::json n) {
    doc["nodes"].push_back(std::move(n));
    return int(doc["nodes"].size()) - 1;
}

void GltfWriter::write(const std::string& path) const {
    static const char* b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string enc;
    for (size_t i = 0; i < bin.size(); i += 3) {
        uint32_t v = uint32_t(uint8_t(bin[i])) << 16;
        if (i + 1 < bin.size()) v |= uint32_t(uint8_t(bin[i + 1])) << 8;
        if (i + 2 < bin.size()) v |= uint32_t(uint8_t(bin[i + 2]));
        enc += b64[(v >> 18) & 63];
        enc += b64[(v >> 12) & 63];
        enc += i + 1 < bin.size() ? b64[(v >> 6) & 63] : '=';
        enc += i + 2 < bin.size() ? b64[v & 63] : '=';
    }
    nlohmann::json out = doc;
    out["buffers"] = {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + enc}}};
    std::ofstream(path) << out.dump(1);
}

}  // namespace testscenes

bool sameBits(const qsgi::Segment& a, const qsgi::Segment& b) {
    const auto floats = [](const qsgi::Segment& s) {
        return std::array<float, 10>{s.origin.x, s.origin.y, s.origin.z, s.direction.x, s.direction.y, s.direction.z,
                                     s.length, s.power.x, s.power.y, s.power.z};
    };
    const auto fa = floats(a), fb = floats(b);
    return std::memcmp(fa.data(), fb.data(), sizeof(float) * fa.size()) == 0 && a.triangle == b.triangle &&
           a.path == b.path && a.bounce == b.bounce && a.impactDynamic == b.impactDynamic;
}

bool sameSegments(const qsgi::RayCache& a, const qsgi::RayCache& b) {
    if (a.pathCount() != b.pathCount() || a.segmentCount() != b.segmentCount()) return false;
    const std::vector<qsgi::Segment> sa = a.decodeAll(), sb = b.decodeAll();
    for (size_t i = 0; i < sa.size(); ++i)
        if (!sameBits(sa[i], sb[i])) return false;
    return true;
}

namespace testscenes {

Scene floorUnderEmitter(int cells, Vec3f centre, float halfX, float halfZ, Vec3f emission, Vec3f albedo) {
    Scene s;
    const uint32_t floor = addMaterial(s, albedo), lamp = addMaterial(s, albedo, emission);
    addGrid(s, s.addNode("Floor", Transform()), {-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, cells, floor);
    // cross(+x, +z) = −y: the front faces the floor.
    addGrid(s, s.addNode("Lamp", Transform()), centre - Vec3f(halfX, 0, halfZ), {2 * halfX, 0, 0}, {0, 0, 2 * halfZ}, 1, lamp);
    s.finalize();
    return s;
}

Scene lampsOverBlocks(int cells, int lamps, int lights, uint64_t seed) {
    Scene s;
    const uint32_t grey = addMaterial(s, Vec3f(0.6f));
    addGrid(s, s.addNode("Floor", Transform()), {-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, cells, grey);
    // Three blocks that shade parts of the floor from parts of the lights.
    for (int k = 0; k < 3; ++k) {
        const int node = s.addNode("Block" + std::to_string(k), Transform::fromTRS(Vec3d(-1.2 + 1.2 * k, 0, 0.3 * (k - 1)), {0, 0, 0, 1}, Vec3d(1, 1, 1)));
        addBoxOnFloor(s, node, 0.25f, 0.5f, 2, grey);
    }
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    auto between = [&](float a, float b) { return a + (b - a) * unit(random); };
    for (int k = 0; k < lamps; ++k) {
        // A small square lamp facing down (cross(+x, +z) = −y), its emission varied tenfold.
        const Vec3f centre(between(-2.5f, 2.5f), between(0.8f, 2.0f), between(-2.5f, 2.5f));
        const float half = between(0.03f, 0.12f);
        const uint32_t lamp = addMaterial(s, Vec3f(0.5f), Vec3f(between(0.5f, 5.0f), between(0.5f, 5.0f), between(0.5f, 5.0f)));
        addGrid(s, s.addNode("Lamp" + std::to_string(k), Transform()), centre - Vec3f(half, 0, half), {2 * half, 0, 0},
                {0, 0, 2 * half}, 1, lamp);
    }
    s.finalize();
    for (int k = 0; k < lights; ++k) {
        PunctualLight l;
        l.name = "light " + std::to_string(k);
        // Some below the floor (they light nothing above it), a third spot lights aimed down.
        l.position = Vec3f(Vec3d(between(-3.0f, 3.0f), between(-0.5f, 2.5f), between(-3.0f, 3.0f)) - s.worldOrigin);
        l.intensity = Vec3f(between(0.05f, 0.5f), between(0.05f, 0.5f), between(0.05f, 0.5f));
        l.type = k % 3 == 2 ? LightType::Spot : LightType::Point;
        l.direction = normalize(Vec3f(between(-0.5f, 0.5f), -1.0f, between(-0.5f, 0.5f)));
        l.cosOuterCone = std::cos(between(0.2f, 1.2f));
        s.lights.push_back(l);
    }
    return s;
}

Scene plateUnderSheet(float plateHalf, int plateCells, float sheetHalf, int sheetCells, float gap, bool sheetFacesUp,
                      Vec3f albedo) {
    Scene s;
    const uint32_t m = addMaterial(s, albedo);
    addGrid(s, s.addNode("Plate", Transform()), {-plateHalf, 0, plateHalf}, {2 * plateHalf, 0, 0}, {0, 0, -2 * plateHalf},
            plateCells, m);
    const int sheet = s.addNode("Sheet", Transform());
    if (sheetFacesUp)  // cross(+x, −z) = +y
        addGrid(s, sheet, {-sheetHalf, gap, sheetHalf}, {2 * sheetHalf, 0, 0}, {0, 0, -2 * sheetHalf}, sheetCells, m);
    else  // cross(+x, +z) = −y
        addGrid(s, sheet, {-sheetHalf, gap, -sheetHalf}, {2 * sheetHalf, 0, 0}, {0, 0, 2 * sheetHalf}, sheetCells, m);
    s.finalize();
    return s;
}

}  // namespace testscenes
