#include "output/ply_writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "output/srgb.h"

namespace qsgi {

PreviewTonemap PreviewTonemap::fromPercentile(const std::vector<Vec3f>& radiosity) {
    std::vector<float> peaks;
    peaks.reserve(radiosity.size());
    for (const Vec3f& b : radiosity) peaks.push_back(maxComponent(b));
    PreviewTonemap t;
    if (peaks.empty()) return t;
    const size_t k = std::min(peaks.size() - 1, size_t(0.99 * double(peaks.size())));
    std::nth_element(peaks.begin(), peaks.begin() + k, peaks.end());
    t.scale = peaks[k] > 0 && std::isfinite(peaks[k]) ? 1.0f / peaks[k] : 1.0f;
    return t;
}

uint8_t PreviewTonemap::encode(float value) const {
    return encodeSrgb8(value * scale);
}

namespace {
template <typename T>
void put(std::string& buf, T v) {
    static_assert(sizeof(T) <= 8);
    char bytes[sizeof(T)];
    std::memcpy(bytes, &v, sizeof(T));  // x86-64 and ARM64 are little-endian, as the format says
    buf.append(bytes, sizeof(T));
}
}  // namespace

std::string encodeVertexRadiosityPly(const Scene& scene, const VertexRadiosity& result, const PreviewTonemap& tonemap) {
    if (result.radiosity.size() != scene.vertexCount() || result.irradiance.size() != scene.vertexCount())
        throw std::logic_error("encodeVertexRadiosityPly: the result does not hold every vertex's radiosity and irradiance");
    // The front vertices; the back sides of doubleSided surfaces as columns beside them (0 where
    // a vertex has none), only in a scene that has some.
    const size_t vertices = scene.frontVertexCount(), triangles = scene.frontTriangleCount();
    const bool backs = scene.backSides.has_value();
    std::ostringstream header;
    header << "ply\nformat binary_little_endian 1.0\ncomment qsgi " << QSGI_VERSION
           << " vertex radiosity (W/m^2)\nelement vertex " << vertices
           << "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
              "property float radiosity_r\nproperty float radiosity_g\nproperty float radiosity_b\n"
              "property float irradiance_r\nproperty float irradiance_g\nproperty float irradiance_b\n"
              "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    if (backs)
        header << "property float back_radiosity_r\nproperty float back_radiosity_g\nproperty float back_radiosity_b\n"
                  "property float back_irradiance_r\nproperty float back_irradiance_g\nproperty float back_irradiance_b\n";
    header << "element face " << triangles << "\nproperty list uchar int vertex_indices\nend_header\n";
    std::string buf = header.str();
    buf.reserve(buf.size() + vertices * (backs ? 75 : 51) + triangles * 13);
    for (size_t v = 0; v < vertices; ++v) {
        const Vec3f p(Vec3d(scene.positions[v]) + scene.worldOrigin);
        const Vec3f& n = scene.normals[v];
        const Vec3f& b = result.radiosity[v];
        const Vec3f& e = result.irradiance[v];
        for (float f : {p.x, p.y, p.z, n.x, n.y, n.z, b.x, b.y, b.z, e.x, e.y, e.z}) put(buf, f);
        for (float f : {b.x, b.y, b.z}) put(buf, tonemap.encode(f));
        if (!backs) continue;
        const uint32_t back = scene.backSides->backVertex[v];
        const bool has = back != Scene::BackSides::kNone;
        const Vec3f bb = has ? result.radiosity[back] : Vec3f(0.0f), be = has ? result.irradiance[back] : Vec3f(0.0f);
        for (float f : {bb.x, bb.y, bb.z, be.x, be.y, be.z}) put(buf, f);
    }
    for (size_t t = 0; t < triangles; ++t) {
        put(buf, uint8_t(3));
        for (uint32_t v : scene.triangles[t].v) put(buf, int32_t(v));
    }
    return buf;
}

}  // namespace qsgi
