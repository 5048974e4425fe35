// The render-ready scene: world-space triangles with materials, lights, the node hierarchy that
// animation moves, and which vertices are dynamic (docs/design.md §2). Built by the glTF loader; the
// tracer and estimators read it and never see file syntax.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scene/camera.h"
#include "scene/environment_light.h"
#include "scene/keyframes.h"
#include "scene/texture.h"
#include "util/vecmath.h"

namespace qsgi {

// glTF's alphaMode: OPAQUE ignores alpha; MASK removes the points whose alpha is below the
// cutoff; BLEND lets 1 − alpha of the light through.
enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

// Lambertian material (docs/inputs.md). At a point, the albedo is albedo × the base colour
// texture's RGB × the vertex colour's RGB, and alpha is alpha × the texture's A × the vertex
// colour's A (lib/scene/surface_lookup.h). emission is the radiance L_e (W m^-2 sr^-1) of the
// front side.
struct Material {
    Material(std::string materialName = {}, Vec3f factor = Vec3f(0.8f), Vec3f radiance = Vec3f(0.0f))
        : name(std::move(materialName)), albedo(factor), emission(radiance) {}
    std::string name;
    Vec3f albedo;  // baseColorFactor's RGB (by itself, the albedo of an untextured surface)
    Vec3f emission;
    float alpha = 1;     // baseColorFactor's A
    TextureSlot baseColour;
    // emission × this texture's RGB (sRGB-decoded) at the point: emission per texel.
    TextureSlot emissive;
    // KHR_materials_transmission: the share of the light that passes straight through (× the
    // texture's R), tinted by the base colour.
    float transmission = 0;
    TextureSlot transmissionTexture;
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f;
    bool doubleSided = false;
    bool isEmissive() const { return maxComponent(emission) > 0; }
    // Rays may pass through it (a cut-out or a blend): SceneBvh asks it at every hit.
    bool letsLightThrough() const { return alphaMode != AlphaMode::Opaque; }
};

struct Triangle {
    uint32_t v[3];
};

// Unit geometric normal of a triangle (CCW winding), turned where needed to the side its vertex
// normals face: the side the surface receives light on.
Vec3f frontFaceNormal(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals, const Triangle& t);

enum class LightType { Point, Spot, Directional };

// A punctual light, static by definition (docs/design.md §2). intensity is W/sr for point and spot
// lights; for directional lights it is the irradiance (W/m^2) on a plane facing the light.
struct PunctualLight {
    std::string name;
    LightType type = LightType::Point;
    Vec3f position{0.0f};
    Vec3f direction{0, -1, 0};  // unit; the direction light travels (spot axis, directional)
    Vec3f intensity{1.0f};
    float cosOuterCone = 0;     // spot lights only
    int node = -1;              // glTF node it hangs from (-1: added by the config)
};

// Places a node's light: at the node's origin, shining down its −Z (spot axis, directional),
// re-centred by the scene's worldOrigin.
void placeLight(PunctualLight& light, const Transform& world, const Vec3d& worldOrigin);

struct SceneNode {
    std::string name;
    int parent = -1;
    std::vector<int> children;
    Transform local;  // rest pose: from the glTF file, then the animation's first frame (setRestPose)
    // glTF's translation, rotation and scale, which animation channels replace one by one
    // (absent when the file gives a matrix, which glTF forbids animating).
    std::optional<NodeTrs> trs;
};

// A glTF skin: the joints (nodes) that pose a skinned mesh, each with its inverse bind matrix.
struct Skin {
    std::string name;
    std::vector<int> joints;
    std::vector<Transform> inverseBind;  // one per joint
};

// One mesh primitive placed by one node: a contiguous block of scene vertices and triangles.
// Object-space data is kept so that a new pose re-places the block exactly:
//   morph targets: p = p₀ + Σ_t w_t Δp_t (normals likewise, then normalised);
//   skin: p_world = (Σ_k ω_k · J(joint_k) · IBM(joint_k)) p, the node's own transform ignored
//   (glTF 2.0 §3.7.3), normals by the inverse-transpose of the blended matrix;
//   otherwise p_world = node world transform · p.
struct MeshInstance {
    int node = -1;
    // Where it came from in the glTF file (-1 for procedural scenes): vertex i of the block is
    // vertex i of meshes[mesh].primitives[primitive] until --subdivide adds vertices after them.
    int mesh = -1, primitive = -1;
    uint32_t firstVertex = 0, vertexCount = 0;
    uint32_t firstTriangle = 0, triangleCount = 0;
    std::vector<Vec3f> objectPositions;
    std::vector<Vec3f> objectNormals;  // empty: area-weighted normals from world triangles
    bool mirrored = false;             // rest transform has a negative determinant

    int skin = -1;              // Scene::skins index, or -1
    int influences = 0;         // joint influences per vertex (4 per JOINTS_n/WEIGHTS_n set)
    std::vector<uint16_t> skinJoints;  // vertex-major, `influences` each: indices into the skin's joints
    std::vector<float> skinWeights;    // the same layout; each vertex's weights sum to 1
    std::vector<std::vector<Vec3f>> morphPositions, morphNormals;  // per target, per vertex (deltas)
    std::vector<double> morphRest;     // the rest pose's target weights

    // --subdivide's new vertices, after the primitive's own: vertex (vertexCount − size + j) is the
    // midpoint of refinedFrom[j]'s two vertices (earlier ones, own or new), so that every attribute
    // of the file can be refined alike (lib/output/refined_attributes.cpp).
    std::vector<std::pair<uint32_t, uint32_t>> refinedFrom;

    // A back side (addBackSides, lib/scene/back_sides.h): the reversed copy of instance `backOf`,
    // whose material is doubleSided; -1 for the instances of the file.
    int backOf = -1;

    bool deforms() const { return skin >= 0 || !morphPositions.empty(); }
};

// A pose of the scene: every node's local transform, and the morph target weights of the nodes an
// animation drives (per node; an empty entry, or none, keeps an instance's rest weights).
struct Pose {
    std::vector<Transform> locals;
    std::vector<std::vector<double>> morphWeights;
    // Implicit from node transforms alone: most poses have no morph weights.
    Pose(std::vector<Transform> nodeLocals = {}, std::vector<std::vector<double>> weights = {})
        : locals(std::move(nodeLocals)), morphWeights(std::move(weights)) {}
};

// The largest bounding-box diagonal qsgi accepts, in scene units. Beyond it float areas and
// densities overflow (a triangle of side 1e19 has an area beyond float range), so a file or an
// animation that places geometry further out is refused rather than rendered to Inf and NaN.
constexpr double kMaxSceneExtent = 1e15;
// The smallest, likewise: the estimators resolve detail down to 10^-6 of the scene's size
// (sceneEpsilon), whose areas must stay normal floats (above 1.2e-38); a scene of 1e-9 units
// keeps them above 1e-30. A scene scaled by 1e-30 reported "no lights" (its lamp's area had
// underflowed to 0) instead of naming its scale.
constexpr double kMinSceneExtent = 1e-9;

// Throws InputError(file, place, …) if any vertex position is non-finite or `bounds` (the scene's
// or its animation's) spans more than kMaxSceneExtent or less than kMinSceneExtent (but not 0).
void checkSceneExtent(const std::vector<Vec3f>& positions, const Bounds3f& bounds, const std::string& file,
                      const std::string& place);

struct Scene {
    std::string sourcePath;

    std::vector<SceneNode> nodes;
    std::vector<MeshInstance> instances;
    std::vector<Material> materials;
    std::vector<PunctualLight> lights;
    // Light from infinitely far away (a sky or an HDR map), from the config or the command line;
    // shared, as a map can be large and a scene is copied whole.
    std::shared_ptr<const EnvironmentLight> environment;
    std::optional<Camera> camera;          // the first camera node's
    std::vector<std::optional<Camera>> cameras;  // by glTF camera index (first node using it)
    std::vector<KeyframeAnimation> animations;             // the file's own (glTF animations)
    std::vector<Skin> skins;

    // World space, current pose, relative to worldOrigin: re-centring keeps float positions
    // precise for scenes far from the origin (docs/design.md §4), so a scene translated by 1e5 m traces
    // exactly as at the origin. Add worldOrigin back when writing positions out.
    Vec3d worldOrigin{0.0};
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;
    std::vector<uint32_t> vertexMaterial;
    std::vector<Triangle> triangles;
    std::vector<uint32_t> triangleMaterial;
    // What the materials' textures read (issue 57): the decoded textures, and per vertex its
    // TEXCOORD_n sets (vertexTexCoords[n], empty when no primitive has set n; a vertex of a
    // primitive without it holds (0, 0)) and its COLOR_0 as linear RGBA (empty when no primitive
    // has one; white elsewhere). Set by the loader, refined with the mesh (--subdivide).
    std::shared_ptr<const TextureSet> textures;
    std::vector<std::vector<TexCoord>> vertexTexCoords;
    std::vector<Rgba> vertexColours;
    // A vertex is hidden while its transform is singular — a zero scale, on any axis, is how glTF
    // animates visibility (docs/design.md §3). A hidden rigid instance is collapsed to its node's origin,
    // so its zero-area triangles block and receive nothing; a skinned vertex goes where its
    // singular blend puts it. Hidden vertices keep their last finite normal and carry radiosity 0
    // (computeRadiosity).
    std::vector<uint8_t> vertexHidden;
    // A sampling mesh's (the vertex fit's, lib/pipeline/vertex_fit_stage.h), else empty: at each of
    // the output's own vertices, its longest incident edge on the output mesh (rest pose); 0 at the
    // samples added between them. The covered-vertex rule (VertexStarts' cover height) judges the
    // output's vertices by it, as a run without the fit does (exactly for a rigid mesh; a deforming
    // one's edges are its rest pose's), and the added samples by their own
    // finer edges: a gap the output cannot resolve covers its vertices, not the samples between.
    std::vector<float> coverEdges;

    // The back sides of doubleSided surfaces (issue 57; lib/scene/back_sides.h): each such instance
    // has a copy with reversed winding and negated normals, appended after every instance of the
    // file, so that every stage lights its back as a surface of its own. The outputs show the
    // front vertices and carry the back values beside them. Absent when no surface is doubleSided.
    struct BackSides {
        uint32_t firstVertex = 0, firstTriangle = 0, firstInstance = 0;
        uint32_t firstMaterial = 0;  // the non-emitting copies of emissive doubleSided materials follow
        std::vector<uint32_t> backVertex;  // per front vertex: its back side's vertex, or kNone
        static constexpr uint32_t kNone = 0xFFFFFFFFu;
    };
    std::optional<BackSides> backSides;
    // What the outputs show: the vertices and triangles before the back sides.
    size_t frontVertexCount() const { return backSides ? backSides->firstVertex : positions.size(); }
    size_t frontTriangleCount() const { return backSides ? backSides->firstTriangle : triangles.size(); }
    size_t frontInstanceCount() const { return backSides ? backSides->firstInstance : instances.size(); }
    size_t frontMaterialCount() const { return backSides ? backSides->firstMaterial : materials.size(); }
    // One of a two-sided pair (a doubleSided triangle and its back side): a ray meets the one that faces it.
    bool twoSided(uint32_t tri) const {
        return backSides && (tri >= backSides->firstTriangle || backSides->backVertex[triangles[tri].v[0]] != BackSides::kNone);
    }
    bool isBackTriangle(uint32_t tri) const { return backSides && tri >= backSides->firstTriangle; }
    bool isBackVertex(uint32_t v) const { return backSides && v >= backSides->firstVertex; }
    // A front instance whose material is doubleSided: the outputs carry its back values (0 where
    // no back side was made: a sealed inside, back_sides.h).
    bool showsBack(const MeshInstance& inst) const {
        return backSides && inst.backOf < 0 && inst.triangleCount > 0 && materials[triangleMaterial[inst.firstTriangle]].doubleSided;
    }

    // Dynamic = under a node the animation moves (docs/design.md §2). Filled by markDynamic.
    std::vector<uint8_t> vertexDynamic;
    std::vector<uint8_t> triangleDynamic;

    size_t vertexCount() const { return positions.size(); }
    size_t triangleCount() const { return triangles.size(); }

    // Bounds of the current pose. Anything that must not change with the pose uses
    // animationBounds instead (docs/design.md §6 step 0).
    Bounds3f bounds() const;
    // Union of the bounds of every pose the run can show: the rest pose after finalize(), every
    // frame once the animation is known (sweepAnimationBounds).
    Bounds3f animationBounds;
    // Boxes that together hold every pose the animation gives the instances it moves: a few per
    // instance, following its way (sweptBoxes, lib/scene/swept_boxes.h). The incremental update's
    // envelope (docs/design.md §6.5).
    std::vector<Bounds3f> sweptBoxes;
    // 10^-6 of animationBounds' diagonal: the tolerance of the estimators' geometric tests (docs/design.md §5).
    float sceneEpsilon() const { return 1e-6f * std::max(animationBounds.extent(), 1e-6f); }

    Vec3f geometricNormal(uint32_t tri) const;  // unit, from the CCW winding (front side)
    // Geometric normals flipped, where needed, to the side the triangle's vertex normals face:
    // the side a surface receives light on (impact count, own surfaces, photon-map filter).
    std::vector<Vec3f> frontFaceNormals() const;
    float triangleArea(uint32_t tri) const;

    // World transform of every node for the given local transforms (one per node).
    std::vector<Transform> worldTransforms(const std::vector<Transform>& locals) const;
    std::vector<Transform> restLocals() const;
    Pose restPose() const { return Pose(restLocals()); }

    // Re-places the instances whose world transform differs from the one they were placed with.
    // Returns true if any vertex moved. If `moved` is given, appends the index of every re-placed
    // instance and, to `movedBounds`, its bounds before and after.
    bool applyPose(const Pose& pose, std::vector<uint32_t>* moved = nullptr,
                   std::vector<Bounds3f>* movedBounds = nullptr);
    Bounds3f instanceBounds(size_t instanceIndex) const;

    // Makes `locals` the rest pose: the run's first frame, so that static geometry is placed once
    // in the pose every frame shows (docs/design.md §6 step 0). Re-places instances, and the lights and
    // cameras hung from nodes.
    void setRestPose(const Pose& pose);

    // Which instances an animation moves: those at or below one of `movedNodes`, skinned ones
    // with a joint there, and morphing ones on one of `morphedNodes`.
    std::vector<uint8_t> dynamicInstances(const std::vector<int>& movedNodes, const std::vector<int>& morphedNodes) const;
    // Marks the vertices/triangles of those instances dynamic.
    void markDynamic(const std::vector<int>& movedNodes, const std::vector<int>& morphedNodes = {});
    bool hasDynamicGeometry() const;

    // Assembly (the glTF loader and procedural scenes use these).
    // Appends a node; returns its index.
    int addNode(std::string name, const Transform& local, int parent = -1);
    // Appends one mesh placed by `node`. indices: CCW triangles in object space; objectNormals
    // may be empty (area-weighted normals are used). World positions are set by finalize().
    // restWorld: the node's rest-pose world transform if the caller has it (a loader walking the
    // hierarchy does), else it is composed up the parents.
    void addInstance(int node, std::vector<Vec3f> objectPositions, std::vector<Vec3f> objectNormals,
                     const std::vector<uint32_t>& indices, uint32_t material, const Transform* restWorld = nullptr);
    // Chooses worldOrigin, places every instance in the rest pose, re-centres lights and camera
    // given in world space, and marks everything static.
    void finalize();

    // Internal: what each instance was last placed with (its node's world transform; a skinned
    // one's joint matrices J·IBM; a morphing one's weights).
    std::vector<Transform> placedWith;
    std::vector<std::vector<Transform>> placedJoints;
    std::vector<std::vector<double>> placedWeights;
    void placeInstance(size_t instanceIndex, const Transform& world, const std::vector<Transform>& jointMatrices,
                       const std::vector<double>& weights);
};

// The most power qsgi carries, in watts: photon powers are floats, and a light's power times the
// scene's emitters and scatterings must stay far below float's 3.4e38.
constexpr double kMaxLightPower = 1e30;
// The most irradiance one emitter may put on a surface, in W/m² (issue 48): what reaches the output
// is radiance and irradiance, not power — a sliver of 10⁻³⁰ m² can carry little power yet have a
// radiance whose πL overflows float. An emissive material's πL_e and a sky's or map's π·(largest
// radiance) (the irradiance it gives a surface open to all of it, at most) must stay below this;
// 10⁸ below float's 3.4·10³⁸, so sums over emitters, bounces and a vertex's neighbours stay finite.
// A point or spot light's I/d² has no such bound before the geometry is posed: the frame's own
// check (RenderJob) refuses a non-finite value before any file is written.
constexpr double kMaxIrradiance = 1e30;
// Throws InputError when a light or emitter carries more than kMaxLightPower (the total too), an
// emissive material or the sky or map has a radiance whose πL exceeds kMaxIrradiance, or a
// point or spot light lies farther from the animation's bounds than kMaxSceneExtent. Messages name
// sceneFile, or configFile for a light the config added (node -1). Needs animationBounds.
void checkLightPowerAndPlace(const Scene& scene, const std::string& sceneFile, const std::string& configFile);

}  // namespace qsgi
