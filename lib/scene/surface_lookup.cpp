#include "scene/surface_lookup.h"

#include <algorithm>

#include "scene/emission_pieces.h"

namespace qsgi {
namespace {

bool textured(const Material& m, const TextureSet* textures) { return readsTexture(m.baseColour, textures); }
bool emissionTextured(const Material& m, const TextureSet* textures) {
    return m.isEmissive() && readsTexture(m.emissive, textures);
}

const Rgba kWhite{1, 1, 1, 1};

TexCoord transformed(const TextureSlot& slot, TexCoord uv) { return slot.transform.identity() ? uv : slot.transform.apply(uv); }

// The texture `slot` names at uv (before the slot's transform).
Rgba readSlot(const TextureSlot& slot, const TextureSet& textures, TexCoord uv, bool srgb) {
    return textures[size_t(slot.texture)].sample(transformed(slot, uv), srgb);
}

// The corners' coordinates interpolated at barycentrics (b0, b1, b2).
TexCoord interpolated(const TexCoord (&uv)[3], float b0, float b1, float b2) {
    return {b0 * uv[0].s + b1 * uv[1].s + b2 * uv[2].s, b0 * uv[0].t + b1 * uv[1].t + b2 * uv[2].t};
}

// Material m's transmission at uv of its transmission texture's set: factor × the texture's R.
float transmissionAt(const Material& m, const TextureSet* textures, TexCoord uv) {
    if (!(m.transmission > 0) || !readsTexture(m.transmissionTexture, textures)) return m.transmission;
    return m.transmission * readSlot(m.transmissionTexture, *textures, uv, false)[0];
}

}  // namespace

bool readsTexture(const TextureSlot& slot, const TextureSet* textures) {
    return slot.used() && textures && size_t(slot.texture) < textures->size() && (*textures)[size_t(slot.texture)].image;
}

TexCoord vertexTexCoord(const Scene& scene, const TextureSlot& slot, uint32_t v) {
    const size_t set = size_t(slot.texCoord);
    return set < scene.vertexTexCoords.size() && v < scene.vertexTexCoords[set].size() ? scene.vertexTexCoords[set][v]
                                                                                        : TexCoord();
}

Rgba baseColourAt(const Material& m, const TextureSet* textures, TexCoord uv, const Rgba& colour) {
    Rgba out{m.albedo.x * colour[0], m.albedo.y * colour[1], m.albedo.z * colour[2], m.alpha * colour[3]};
    if (textured(m, textures)) {
        const Rgba texel = readSlot(m.baseColour, *textures, uv, true);
        for (size_t c = 0; c < 4; ++c) out[c] *= texel[c];
    }
    if (m.alphaMode == AlphaMode::Opaque) out[3] = 1;
    return out;
}

Vec3f vertexAlbedo(const Scene& scene, uint32_t v) {
    const Material& m = scene.materials[scene.vertexMaterial[v]];
    const bool coloured = !scene.vertexColours.empty();
    Vec3f albedo = m.albedo;
    if (coloured || textured(m, scene.textures.get())) {
        const Rgba c = baseColourAt(m, scene.textures.get(), vertexTexCoord(scene, m.baseColour, v), coloured ? scene.vertexColours[v] : kWhite);
        albedo = Vec3f(c[0], c[1], c[2]);
        if (m.alphaMode == AlphaMode::Blend) albedo = albedo * c[3];  // a BLEND reflects its alpha share
    } else if (m.alphaMode == AlphaMode::Blend) {
        albedo = albedo * m.alpha;
    }
    if (!(m.transmission > 0)) return albedo;
    return albedo * (1 - transmissionAt(m, scene.textures.get(), vertexTexCoord(scene, m.transmissionTexture, v)));
}

SurfaceLookup::SurfaceLookup(const Scene& scene) {
    const TextureSet* textures = scene.textures.get();
    const bool coloured = !scene.vertexColours.empty();
    bool needed = coloured;
    for (const Material& m : scene.materials)
        needed = needed || textured(m, textures) || emissionTextured(m, textures) || m.letsLightThrough() ||
                 m.transmission > 0;
    if (!needed) return;
    materials_ = scene.materials;
    textures_ = scene.textures;
    triangleMaterial_ = scene.triangleMaterial;
    cornerOf_.assign(scene.triangleCount(), kUniform);
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const Material& m = scene.materials[scene.triangleMaterial[t]];
        anyTransmits_ = anyTransmits_ || m.transmission > 0;
        anyBlends_ = anyBlends_ || m.alphaMode == AlphaMode::Blend;
        const bool transmissionTextured = m.transmission > 0 && readsTexture(m.transmissionTexture, textures);
        if (!coloured && !textured(m, textures) && !emissionTextured(m, textures) && !transmissionTextured) continue;
        Corners c;
        for (size_t k = 0; k < 3; ++k) {
            const uint32_t v = scene.triangles[t].v[k];
            c.uv[k] = vertexTexCoord(scene, m.baseColour, v);
            c.emissiveUv[k] = vertexTexCoord(scene, m.emissive, v);
            c.transmissionUv[k] = vertexTexCoord(scene, m.transmissionTexture, v);
            c.colour[k] = coloured ? scene.vertexColours[v] : kWhite;
        }
        cornerOf_[t] = uint32_t(corners_.size());
        corners_.push_back(c);
    }
}

Rgba SurfaceLookup::baseColour(uint32_t t, float b1, float b2) const {
    const Material& m = materials_[triangleMaterial_[t]];
    if (cornerOf_[t] == kUniform) return {m.albedo.x, m.albedo.y, m.albedo.z, m.alphaMode == AlphaMode::Opaque ? 1.0f : m.alpha};
    const Corners& c = corners_[cornerOf_[t]];
    const float b0 = std::max(0.0f, 1.0f - b1 - b2);
    const TexCoord uv = interpolated(c.uv, b0, b1, b2);
    Rgba colour;
    for (size_t k = 0; k < 4; ++k) colour[k] = b0 * c.colour[0][k] + b1 * c.colour[1][k] + b2 * c.colour[2][k];
    return baseColourAt(m, textures_.get(), uv, colour);
}

Vec3f SurfaceLookup::emission(uint32_t t, float b1, float b2) const {
    const Material& m = materials_[triangleMaterial_[t]];
    if (cornerOf_[t] == kUniform || !emissionTextured(m, textures_.get())) return m.emission;
    const Corners& c = corners_[cornerOf_[t]];
    const float b0 = std::max(0.0f, 1.0f - b1 - b2);
    return emissionAt(m, textures_.get(), transformed(m.emissive, interpolated(c.emissiveUv, b0, b1, b2)));
}

float SurfaceLookup::transmission(uint32_t t, float b1, float b2) const {
    const Material& m = materials_[triangleMaterial_[t]];
    if (cornerOf_[t] == kUniform) return m.transmission;
    const Corners& c = corners_[cornerOf_[t]];
    const float b0 = std::max(0.0f, 1.0f - b1 - b2);
    return transmissionAt(m, textures_.get(), interpolated(c.transmissionUv, b0, b1, b2));
}

float SurfaceLookup::reflectedShare(uint32_t t, float b1, float b2) const {
    const float kept = blends(t) ? baseColour(t, b1, b2)[3] : 1.0f;
    return transmits(t) ? kept * (1 - transmission(t, b1, b2)) : kept;
}

bool SurfaceLookup::stops(uint32_t t, float b1, float b2, float choice) const {
    const Material& m = materials_[triangleMaterial_[t]];
    if (m.alphaMode == AlphaMode::Opaque) return true;
    const float alpha = baseColour(t, b1, b2)[3];
    return m.alphaMode == AlphaMode::Mask ? alpha >= m.alphaCutoff : alpha > choice;
}

size_t SurfaceLookup::bytes() const {
    // The textures are the scene's, shared: counted with it.
    return triangleMaterial_.capacity() * sizeof(uint32_t) + cornerOf_.capacity() * sizeof(uint32_t) +
           corners_.capacity() * sizeof(Corners) + materials_.capacity() * sizeof(Material);
}

}  // namespace qsgi
