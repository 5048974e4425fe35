// frame_NNNN.ply (docs/design.md §7): binary little-endian; vertex x y z nx ny nz, radiosity_r/g/b
// (W/m^2), irradiance_r/g/b (W/m^2, the light arriving, before the albedo) and a tonemapped red green blue preview; faces as vertex_indices.
#pragma once

#include <string>

#include "estimate/vertex_radiosity.h"
#include "scene/scene.h"

namespace qsgi {

// Maps radiosity to the 8-bit preview colours: B * scale, clamped, sRGB-encoded. One scale for a
// whole animation keeps the preview from flickering between frames.
struct PreviewTonemap {
    float scale = 1;
    // Scale that puts the 99th percentile of the vertices' largest radiosity component at white.
    static PreviewTonemap fromPercentile(const std::vector<Vec3f>& radiosity);
    uint8_t encode(float value) const;
};

// The file's bytes (OutputDirectory::write puts them on disk).
std::string encodeVertexRadiosityPly(const Scene& scene, const VertexRadiosity& result, const PreviewTonemap& tonemap);

}  // namespace qsgi
