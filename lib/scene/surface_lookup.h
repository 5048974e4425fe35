// What a surface's material says at a point (docs/inputs.md, issue 57): its albedo and alpha from
// baseColorFactor × baseColorTexture at the point's UV × COLOR_0 there, the UV and vertex colour
// interpolated over the triangle. One rule for every reader: a photon's bounce, a gather ray's hit,
// a vertex's radiosity, a ray meeting a cut-out or a blend (SceneBvh), the camera's pixel.
//
// SurfaceLookup keeps its own copy of what it reads (materials, textures, each varying
// triangle's corners), so that the tracer's and the BVH's copies outlive any scene they were made
// from; the corners are static (a pose moves positions, never UVs or colours).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "scene/scene.h"

namespace qsgi {

// Material m's base colour (linear RGB albedo, alpha) at texture coordinate `uv` (of the set its
// base colour texture reads) and vertex colour `colour`. Alpha under OPAQUE is 1.
Rgba baseColourAt(const Material& m, const TextureSet* textures, TexCoord uv, const Rgba& colour);

// Texture `slot` reads an image `textures` holds.
bool readsTexture(const TextureSlot& slot, const TextureSet* textures);
// Vertex v's coordinates in the TEXCOORD set `slot` reads (before its transform; (0, 0) if the
// scene has no such set).
TexCoord vertexTexCoord(const Scene& scene, const TextureSlot& slot, uint32_t v);

// Vertex v's own diffuse reflectance: its material's base colour at its UV and colour, times the
// share of the light it does not let through (1 − T of a pane, alpha of a BLEND). A vertex's
// radiosity is this times E_v.
Vec3f vertexAlbedo(const Scene& scene, uint32_t v);

class SurfaceLookup {
public:
    explicit SurfaceLookup(const Scene& scene);

    // Some triangle's albedo or alpha varies over it, or some surface lets light through: false
    // for a scene of plain colour factors, whose readers keep their per-material arithmetic.
    bool any() const { return !cornerOf_.empty(); }
    // The albedo, alpha or emission varies over triangle t (a texture, vertex colours).
    bool varies(uint32_t t) const { return !cornerOf_.empty() && cornerOf_[t] != kUniform; }
    // Light passes straight through triangle t in part (KHR_materials_transmission).
    bool transmits(uint32_t t) const { return any() && materials_[triangleMaterial_[t]].transmission > 0; }
    bool anyTransmits() const { return anyTransmits_; }
    // Triangle t is an alpha BLEND.
    bool blends(uint32_t t) const { return any() && materials_[triangleMaterial_[t]].alphaMode == AlphaMode::Blend; }
    bool anyBlends() const { return anyBlends_; }
    // The share that passes at (b1, b2): transmission × its texture's R there (linear).
    float transmission(uint32_t t, float b1, float b2) const;
    // Rays may pass through triangle t (MASK or BLEND).
    bool letsLightThrough(uint32_t t) const { return any() && materials_[triangleMaterial_[t]].letsLightThrough(); }

    // Triangle t's base colour at barycentrics (b1, b2) of its vertices 1 and 2.
    Rgba baseColour(uint32_t t, float b1, float b2) const;
    Vec3f albedo(uint32_t t, float b1, float b2) const {
        const Rgba c = baseColour(t, b1, b2);
        return Vec3f(c[0], c[1], c[2]);
    }
    // Triangle t's emitted radiance L_e at (b1, b2): its emissive texture's texel there.
    Vec3f emission(uint32_t t, float b1, float b2) const;
    // The share of the light arriving at (b1, b2) that triangle t reflects diffusely (× its base
    // colour): 1 − T of a pane, alpha of a BLEND, both of a surface that is both; 1 elsewhere.
    float reflectedShare(uint32_t t, float b1, float b2) const;
    // Whether a ray meets triangle t at (b1, b2): always, unless its material lets light through —
    // MASK: where alpha ≥ alphaCutoff; BLEND: where alpha > `choice`, a number in [0, 1) of the
    // ray's own (so that a share alpha of the rays stops there, each ray deciding the same way
    // every time it is cast).
    bool stops(uint32_t t, float b1, float b2, float choice) const;

    size_t bytes() const;

private:
    static constexpr uint32_t kUniform = 0xFFFFFFFFu;
    struct Corners {
        TexCoord uv[3];          // the base colour texture's set
        TexCoord emissiveUv[3];  // the emissive texture's
        TexCoord transmissionUv[3];
        Rgba colour[3];
    };
    std::vector<Material> materials_;
    std::shared_ptr<const TextureSet> textures_;
    std::vector<uint32_t> triangleMaterial_;
    std::vector<uint32_t> cornerOf_;  // per triangle: its Corners, or kUniform
    std::vector<Corners> corners_;
    bool anyTransmits_ = false, anyBlends_ = false;
};

}  // namespace qsgi
