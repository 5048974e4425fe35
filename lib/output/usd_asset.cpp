#include "output/usd_asset.h"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <map>

#include "output/frame_readback.h"
#include "output/usd_identifiers.h"

namespace qsgi {

namespace {

// The layer's text, handed on in pieces of about a megabyte: a long animation's samples are never
// held whole.
class UsdText {
public:
    explicit UsdText(const std::function<void(std::string_view)>& put) : put_(put) {}
    UsdText& operator<<(std::string_view text) {
        text_ += text;
        if (text_.size() >= kPiece) flush();
        return *this;
    }
    UsdText& operator<<(long long value) { return append(value); }
    UsdText& operator<<(float value) { return append(value); }
    UsdText& operator<<(double value) { return append(value); }
    void flush() {
        bytes_ += text_.size();
        if (!text_.empty()) put_(text_);
        text_.clear();
    }
    uint64_t bytes() const { return bytes_ + text_.size(); }

private:
    static constexpr size_t kPiece = size_t(1) << 20;
    // std::to_chars without a precision: the shortest text that reads back to the same value.
    template <typename T>
    UsdText& append(T value) {
        char digits[32];
        const std::to_chars_result end = std::to_chars(digits, digits + sizeof digits, value);
        return *this << std::string_view(digits, size_t(end.ptr - digits));
    }

    const std::function<void(std::string_view)>& put_;
    std::string text_;
    uint64_t bytes_ = 0;
};

UsdText& operator<<(UsdText& text, const Vec3f& v) { return text << "(" << v.x << "," << v.y << "," << v.z << ")"; }

// A USD matrix4d is row-vector (p' = p M): its rows are the columns of qsgi's column-vector
// Transform, which stores them in that order.
UsdText& operator<<(UsdText& text, const Transform& t) {
    text << "(";
    for (int column = 0; column < 4; ++column) {
        text << (column ? ", (" : "(");
        for (int row = 0; row < 4; ++row) text << (row ? "," : "") << t.at(row, column);
        text << ")";
    }
    return text << ")";
}

void writeArray(UsdText& text, const Vec3f* values, size_t count) {
    text << "[";
    for (size_t i = 0; i < count; ++i) text << (i ? "," : "") << values[i];
    text << "]";
}

// A string literal of the text format: quotes and backslashes escaped, control characters as \x.
std::string quoted(const std::string& s) {
    std::string out = "\"";
    for (const char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        if (static_cast<unsigned char>(c) < 0x20) {
            char escape[8];
            std::snprintf(escape, sizeof escape, "\\x%02x", unsigned(static_cast<unsigned char>(c)));
            out += escape;
        } else
            out += c;
    }
    return out + "\"";
}

// How a mesh is posed: rigid ones by their node's transform over object-space points; skinned and
// morphing ones by their points, in world space (their node's transform does not place them).
enum class Placement { Object, World };

struct MeshPlan {
    size_t instance = 0;
    std::string name;          // unique within its node
    std::string materialPath;  // </Scene/Materials/…>
    Placement placement = Placement::Object;
};

struct NodePlan {
    std::string name;  // unique under /Scene
    std::vector<MeshPlan> meshes;
};

// A mesh's frames, as one pass over the PLYs reads them: frame-major, the mesh's vertices each.
struct MeshFrames {
    std::vector<Vec3f> radiance, irradiance;
    std::vector<Vec3f> backRadiance, backIrradiance;  // a doubleSided mesh's back side (lib/scene/back_sides.h)
    std::vector<Vec3f> points, normals;  // Placement::World only
    std::vector<Transform> transforms;   // Placement::Object only: the node's world transform
};

// The transform that places a rigid mesh as the scene does: a singular one (a scale of zero on
// some axis: how glTF hides a node) collapses the mesh to its node's origin, as Scene::placeInstance
// does, rather than leaving a flat sheet in view.
Transform placing(const Transform& world) {
    if (world.isInvertible()) return world;
    Transform collapsed;
    collapsed.m.fill(0);
    for (int row = 0; row < 4; ++row) collapsed.at(row, 3) = world.at(row, 3);
    return collapsed;
}

template <typename T>
bool allFramesEqual(const std::vector<T>& values, size_t perFrame, size_t frames) {
    for (size_t f = 1; f < frames; ++f)
        if (std::memcmp(&values[f * perFrame], &values[0], perFrame * sizeof(T)) != 0) return false;
    return true;
}

Bounds3f boundsOf(const Vec3f* points, size_t count) {
    Bounds3f b;
    for (size_t i = 0; i < count; ++i) b.extend(points[i]);
    return b.empty() ? Bounds3f{Vec3f(0.0f), Vec3f(0.0f)} : b;
}

void writeExtent(UsdText& text, const Bounds3f& b) { text << "[" << b.lower << "," << b.upper << "]"; }

// One vertex attribute, its value or its samples at every frame.
void writeVertexArray(UsdText& text, const char* type, const char* name, bool primvar, const std::vector<Vec3f>& values,
                      size_t perFrame, const UsdAssetSettings& settings, bool sampled) {
    const size_t frames = size_t(settings.last - settings.first + 1);
    const char* interpolation = " (\n                interpolation = \"vertex\"\n            )\n";
    if (!sampled) {
        text << "            " << type << " " << name << " = ";
        writeArray(text, values.data(), perFrame);
        text << (primvar ? interpolation : "\n");
        return;
    }
    if (primvar) text << "            " << type << " " << name << interpolation;
    text << "            " << type << " " << name << ".timeSamples = {\n";
    for (size_t f = 0; f < frames; ++f) {
        text << "                " << (long long)(settings.first + int(f)) << ": ";
        writeArray(text, values.data() + f * perFrame, perFrame);
        text << ",\n";
    }
    text << "            }\n";
}

void writeMesh(UsdText& text, const Scene& scene, const MeshPlan& plan, const MeshFrames& data, const UsdAssetSettings& settings) {
    const MeshInstance& inst = scene.instances[plan.instance];
    const size_t frames = size_t(settings.last - settings.first + 1);
    const size_t n = inst.vertexCount;
    text << "        def Mesh \"" << plan.name << "\" (\n            prepend apiSchemas = [\"MaterialBindingAPI\"]\n        )\n        {\n";

    const bool world = plan.placement == Placement::World;
    const bool pointsMove = world && !allFramesEqual(data.points, n, frames);
    // extent: the bounds of the points, sampled with them.
    if (!world) {
        text << "            float3[] extent = ";
        writeExtent(text, boundsOf(inst.objectPositions.data(), n));
        text << "\n";
    } else if (!pointsMove) {
        text << "            float3[] extent = ";
        writeExtent(text, boundsOf(data.points.data(), n));
        text << "\n";
    } else {
        text << "            float3[] extent.timeSamples = {\n";
        for (size_t f = 0; f < frames; ++f) {
            text << "                " << (long long)(settings.first + int(f)) << ": ";
            writeExtent(text, boundsOf(data.points.data() + f * n, n));
            text << ",\n";
        }
        text << "            }\n";
    }

    // A triangle naming a vertex twice has no area and carries nothing; USD calls such a face
    // invalid, and Blender's importer, correcting it, drops the mesh's primvars (or crashes).
    std::vector<Triangle> faces;
    for (uint32_t t = 0; t < inst.triangleCount; ++t) {
        Triangle tri = scene.triangles[inst.firstTriangle + t];
        if (tri.v[0] == tri.v[1] || tri.v[1] == tri.v[2] || tri.v[0] == tri.v[2]) continue;
        // The scene turned a mirrored instance's triangles to face the same way in world space;
        // over object-space points under its transform, the file's own order is right (USD, like
        // glTF, reverses the winding of a transform with a negative determinant).
        if (!world && inst.mirrored) std::swap(tri.v[1], tri.v[2]);
        faces.push_back(tri);
    }
    text << "            int[] faceVertexCounts = [";
    for (size_t t = 0; t < faces.size(); ++t) text << (t ? ",3" : "3");
    text << "]\n            int[] faceVertexIndices = [";
    for (size_t t = 0; t < faces.size(); ++t)
        for (int k = 0; k < 3; ++k) text << (t || k ? "," : "") << (long long)(faces[t].v[k] - inst.firstVertex);
    text << "]\n            rel material:binding = <" << plan.materialPath << ">\n";

    if (world)
        writeVertexArray(text, "normal3f[]", "normals", true, data.normals, n, settings,
                         !allFramesEqual(data.normals, n, frames));
    else if (inst.objectNormals.size() == n)
        writeVertexArray(text, "normal3f[]", "normals", true, inst.objectNormals, n, settings, false);
    if (world)
        writeVertexArray(text, "point3f[]", "points", false, data.points, n, settings, pointsMove);
    else
        writeVertexArray(text, "point3f[]", "points", false, inst.objectPositions, n, settings, false);
    if (!data.backRadiance.empty()) {
        writeVertexArray(text, "color3f[]", "primvars:backIrradiance", true, data.backIrradiance, n, settings, true);
        writeVertexArray(text, "color3f[]", "primvars:backRadiance", true, data.backRadiance, n, settings, true);
    }
    writeVertexArray(text, "color3f[]", "primvars:irradiance", true, data.irradiance, n, settings, true);
    writeVertexArray(text, "color3f[]", "primvars:radiance", true, data.radiance, n, settings, true);
    text << "            custom int qsgi:firstVertex = " << (long long)inst.firstVertex << "\n";
    text << "            custom int qsgi:vertexCount = " << (long long)n << "\n";
    text << "            uniform token subdivisionScheme = \"none\"\n";
    if (!world) {
        if (std::all_of(data.transforms.begin(), data.transforms.end(), [&](const Transform& t) { return t == data.transforms[0]; }))
            text << "            matrix4d xformOp:transform = " << data.transforms[0] << "\n";
        else {
            text << "            matrix4d xformOp:transform.timeSamples = {\n";
            for (size_t f = 0; f < frames; ++f)
                text << "                " << (long long)(settings.first + int(f)) << ": " << data.transforms[f] << ",\n";
            text << "            }\n";
        }
        text << "            uniform token[] xformOpOrder = [\"xformOp:transform\"]\n";
    }
    text << "        }\n";
}

void writeMaterial(UsdText& text, const std::string& name) {
    const std::string path = "/Scene/Materials/" + name;
    text << "        def Material \"" << name << "\"\n        {\n"
         << "            token outputs:surface.connect = <" << path << "/Surface.outputs:surface>\n\n"
         << "            def Shader \"Surface\"\n            {\n"
         << "                uniform token info:id = \"UsdPreviewSurface\"\n"
         << "                color3f inputs:diffuseColor = (0, 0, 0)\n"
         << "                color3f inputs:emissiveColor.connect = <" << path << "/Radiance.outputs:result>\n"
         << "                float inputs:ior = 1\n"
         << "                token outputs:surface\n            }\n\n"
         << "            def Shader \"Radiance\"\n            {\n"
         << "                uniform token info:id = \"UsdPrimvarReader_float3\"\n"
         << "                string inputs:varname = \"radiance\"\n"
         << "                float3 outputs:result\n            }\n        }\n";
}

}  // namespace

void writeUsdAsset(const Scene& scene, const UsdAssetSettings& settings,
                   const std::function<VertexRadiosityPly(int frame)>& frameAt,
                   const std::function<void(std::string_view)>& put, UsdAssetSummary* summary) {
    const size_t frames = size_t(settings.last - settings.first + 1);

    // Materials, in the order the meshes first use them.
    UniqueNames materialNames;
    std::map<uint32_t, std::string> materialName;
    std::vector<std::string> materialOrder;
    // Nodes in the order of their first mesh; meshes in scene order within a node.
    UniqueNames nodeNames;
    nodeNames.claim("Materials");  // /Scene/Materials is taken: a node of that name becomes Materials_1
    std::map<int, size_t> nodeIndex;
    std::vector<NodePlan> nodes;
    std::vector<UniqueNames> meshNames;
    for (size_t i = 0; i < scene.frontInstanceCount(); ++i) {  // the back sides are the fronts' (back_sides.h)
        const MeshInstance& inst = scene.instances[i];
        auto [at, isNew] = nodeIndex.emplace(inst.node, nodes.size());
        if (isNew) {
            const std::string name = inst.node >= 0 ? scene.nodes[size_t(inst.node)].name : std::string();
            nodes.push_back(NodePlan{nodeNames.claim(usdIdentifier(name, "Node")), {}});
            meshNames.emplace_back();
        }
        const uint32_t material = inst.triangleCount > 0 ? scene.triangleMaterial[inst.firstTriangle]
                                  : inst.vertexCount > 0 ? scene.vertexMaterial[inst.firstVertex]
                                                         : 0;
        auto [m, newMaterial] = materialName.emplace(material, std::string());
        if (newMaterial) {
            const std::string name = material < scene.materials.size() ? scene.materials[material].name : std::string();
            m->second = materialNames.claim(usdIdentifier(name, "Material"));
            materialOrder.push_back(m->second);
        }
        MeshPlan plan;
        plan.instance = i;
        const std::string meshName =
            inst.mesh >= 0 && size_t(inst.mesh) < settings.meshNames.size() ? settings.meshNames[size_t(inst.mesh)] : std::string();
        plan.name = meshNames[at->second].claim(usdIdentifier(meshName, "Mesh"));
        plan.materialPath = "/Scene/Materials/" + m->second;
        plan.placement = inst.deforms() ? Placement::World : Placement::Object;
        nodes[at->second].meshes.push_back(std::move(plan));
    }

    UsdText text(put);
    text << "#usda 1.0\n(\n    customLayerData = {\n        string \"qsgi:version\" = " << quoted(QSGI_VERSION)
         << "\n    }\n    defaultPrim = \"Scene\"\n    doc = "
         << quoted(std::string("qsgi ") + QSGI_VERSION + ": the vertex bake of " + settings.source +
                   ", frames " + std::to_string(settings.first) + " to " + std::to_string(settings.last) +
                   ". primvars:radiance is B/pi (W m^-2 sr^-1, what a Lambertian surface shows), primvars:irradiance "
                   "is E (W m^-2, the light arriving, before the albedo); qsgi:firstVertex says which vertices of the "
                   "frame_NNNN.ply files a mesh holds.")
         << "\n    endTimeCode = " << (long long)settings.last << "\n";
    if (settings.fps > 0) text << "    framesPerSecond = " << settings.fps << "\n";
    text << "    metersPerUnit = 1\n    startTimeCode = " << (long long)settings.first << "\n";
    if (settings.fps > 0) text << "    timeCodesPerSecond = " << settings.fps << "\n";
    text << "    upAxis = \"Y\"\n)\n\ndef Xform \"Scene\" (\n    kind = \"assembly\"\n)\n{\n    def Scope \"Materials\"\n    {\n";
    for (const std::string& name : materialOrder) writeMaterial(text, name);
    text << "    }\n";

    // Meshes in groups whose frames fit the budget; one pass over the frames' PLYs per group.
    struct Ref {
        size_t node, mesh;
    };
    std::vector<Ref> order;
    for (size_t n = 0; n < nodes.size(); ++n)
        for (size_t m = 0; m < nodes[n].meshes.size(); ++m) order.push_back(Ref{n, m});
    auto heldBytes = [&](const Ref& r) {
        const MeshPlan& plan = nodes[r.node].meshes[r.mesh];
        const MeshInstance& inst = scene.instances[plan.instance];
        const bool back = scene.showsBack(inst);
        const uint64_t perFrame = uint64_t(inst.vertexCount) * sizeof(Vec3f) *
                                  ((plan.placement == Placement::World ? 4 : 2) + (back ? 2 : 0)) + sizeof(Transform);
        return perFrame * frames;
    };
    size_t passes = 0, points = 0;
    size_t openNode = SIZE_MAX;
    for (size_t begin = 0; begin < order.size();) {
        size_t end = begin;
        uint64_t held = 0;
        while (end < order.size() && (end == begin || held + heldBytes(order[end]) <= settings.memoryBudget))
            held += heldBytes(order[end++]);

        std::vector<MeshFrames> data(end - begin);
        for (size_t f = 0; f < frames; ++f) {
            const int frame = settings.first + int(f);
            const VertexRadiosityPly ply = frameAt(frame);
            std::vector<Transform> worlds;
            for (size_t k = begin; k < end; ++k) {
                const MeshPlan& plan = nodes[order[k].node].meshes[order[k].mesh];
                const MeshInstance& inst = scene.instances[plan.instance];
                MeshFrames& d = data[k - begin];
                const size_t first = inst.firstVertex, n = inst.vertexCount;
                if (f == 0) {
                    d.radiance.reserve(n * frames);
                    d.irradiance.reserve(n * frames);
                }
                for (size_t v = first; v < first + n; ++v) d.radiance.push_back(bakedRadiance(ply.radiosity[v]));
                d.irradiance.insert(d.irradiance.end(), ply.irradiance.begin() + long(first), ply.irradiance.begin() + long(first + n));
                if (!ply.backRadiosity.empty() && scene.showsBack(inst)) {
                    for (size_t v = first; v < first + n; ++v) d.backRadiance.push_back(bakedRadiance(ply.backRadiosity[v]));
                    d.backIrradiance.insert(d.backIrradiance.end(), ply.backIrradiance.begin() + long(first),
                                            ply.backIrradiance.begin() + long(first + n));
                }
                if (plan.placement == Placement::World) {
                    d.points.insert(d.points.end(), ply.positions.begin() + long(first), ply.positions.begin() + long(first + n));
                    d.normals.insert(d.normals.end(), ply.normals.begin() + long(first), ply.normals.begin() + long(first + n));
                } else {
                    if (worlds.empty()) worlds = settings.nodeWorldAt(frame);
                    d.transforms.push_back(placing(inst.node >= 0 ? worlds[size_t(inst.node)] : Transform()));
                }
            }
        }
        ++passes;

        for (size_t k = begin; k < end; ++k) {
            const Ref& r = order[k];
            if (openNode != r.node) {
                if (openNode != SIZE_MAX) text << "    }\n";
                text << "\n    def Xform \"" << nodes[r.node].name << "\"\n    {\n";
                openNode = r.node;
            } else
                text << "\n";
            const MeshPlan& plan = nodes[r.node].meshes[r.mesh];
            writeMesh(text, scene, plan, data[k - begin], settings);
            points += scene.instances[plan.instance].vertexCount;
            data[k - begin] = MeshFrames();  // written: its frames go
        }
        begin = end;
    }
    if (openNode != SIZE_MAX) text << "    }\n";
    text << "}\n";
    text.flush();
    if (summary) {
        summary->bytes = text.bytes();
        summary->meshes = order.size();
        summary->points = points;
        summary->frames = frames;
        summary->framePasses = passes;
    }
}

}  // namespace qsgi
