// Emission per texel (issue 57, docs/inputs.md): an emissive triangle whose material has an
// emissive texture is cut into pieces over which its radiance is constant, and each piece is an
// emitter of its own, chosen by its power as every emitter is (photon emission, LightSampler;
// exact direct light, DirectLight). A texture that is black but for a screen then emits from the
// screen alone, and a triangle whose texels are all black is no emitter.
//
// The cut follows the texture's texel grid in (transformed) texture space: under NEAREST each
// piece lies within one texel and carries exactly that texel's radiance, so the triangle's power
// is the integral of its texels over it. Under bilinear filtering a piece carries the radiance at
// its centroid (the bilinear surface taken piecewise constant per texel: exact in the mean over a
// texel's neighbourhood, not within it). A triangle that spans more than kMostCells texels is cut
// along a coarser grid (blocks of texels, each block's value at its piece's centroid): a bound on
// the emitters a huge screen texture makes.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace qsgi {

struct EmissionPiece {
    uint32_t triangle = 0;
    // Its corners as barycentrics (b1, b2) of the scene triangle's vertices 1 and 2.
    std::array<std::array<float, 2>, 3> corner{};
    float areaShare = 1;   // its area over the triangle's
    Vec3f radiance{0.0f};  // L_e, W m⁻² sr⁻¹
};

constexpr size_t kMostCells = 4096;

// The pieces of triangle t with some radiance: the whole triangle at its material's emission when
// it has no emissive texture (or none that could be read), none when it emits nothing.
std::vector<EmissionPiece> emissionPieces(const Scene& scene, uint32_t t);

// Material m's radiance at texture coordinate uv of its emissive texture's set.
Vec3f emissionAt(const Material& m, const TextureSet* textures, TexCoord uv);
// Vertex v's own radiance (its material at its UV): its radiosity's π L_e.
Vec3f vertexEmission(const Scene& scene, uint32_t v);

}  // namespace qsgi
