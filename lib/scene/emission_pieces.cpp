#include "scene/emission_pieces.h"

#include <algorithm>
#include <cmath>

#include "scene/surface_lookup.h"

namespace qsgi {
namespace {

struct Point2 {
    double x, y;
};

const Texture* emissiveTexture(const Material& m, const TextureSet* textures) {
    return readsTexture(m.emissive, textures) ? &(*textures)[size_t(m.emissive.texture)] : nullptr;
}

// Vertex v's coordinates in the emissive texture's space (transformed).
TexCoord uvOf(const Scene& scene, const TextureSlot& slot, uint32_t v) {
    const TexCoord uv = vertexTexCoord(scene, slot, v);
    return slot.transform.identity() ? uv : slot.transform.apply(uv);
}

// The part of convex polygon `in` where a·p ≥ c along axis (x when `alongX`), Sutherland–Hodgman.
std::vector<Point2> clipped(const std::vector<Point2>& in, bool alongX, double bound, bool keepAbove) {
    std::vector<Point2> out;
    auto inside = [&](const Point2& p) { return keepAbove ? (alongX ? p.x : p.y) >= bound : (alongX ? p.x : p.y) <= bound; };
    for (size_t i = 0; i < in.size(); ++i) {
        const Point2 &a = in[i], &b = in[(i + 1) % in.size()];
        const bool ina = inside(a), inb = inside(b);
        if (ina) out.push_back(a);
        if (ina != inb) {
            const double va = alongX ? a.x : a.y, vb = alongX ? b.x : b.y;
            const double s = (bound - va) / (vb - va);
            out.push_back({a.x + s * (b.x - a.x), a.y + s * (b.y - a.y)});
        }
    }
    return out;
}

double polygonArea(const std::vector<Point2>& p) {
    double twice = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        const Point2 &a = p[i], &b = p[(i + 1) % p.size()];
        twice += a.x * b.y - b.x * a.y;
    }
    return 0.5 * std::abs(twice);
}

}  // namespace

Vec3f emissionAt(const Material& m, const TextureSet* textures, TexCoord uv) {
    const Texture* texture = emissiveTexture(m, textures);
    if (!texture) return m.emission;
    const Rgba texel = texture->sample(uv, true);
    return m.emission * Vec3f(texel[0], texel[1], texel[2]);
}

Vec3f vertexEmission(const Scene& scene, uint32_t v) {
    const Material& m = scene.materials[scene.vertexMaterial[v]];
    if (!m.isEmissive() || !emissiveTexture(m, scene.textures.get())) return m.emission;
    return emissionAt(m, scene.textures.get(), uvOf(scene, m.emissive, v));
}

std::vector<EmissionPiece> emissionPieces(const Scene& scene, uint32_t t) {
    const Material& m = scene.materials[scene.triangleMaterial[t]];
    std::vector<EmissionPiece> pieces;
    if (!m.isEmissive()) return pieces;
    const Texture* texture = emissiveTexture(m, scene.textures.get());
    if (!texture) {
        EmissionPiece whole;
        whole.triangle = t;
        whole.corner = {{{0, 0}, {1, 0}, {0, 1}}};
        whole.radiance = m.emission;
        pieces.push_back(whole);
        return pieces;
    }
    // The triangle in texel units of the texture (transformed UVs times the image's size).
    const double w = texture->image->width, h = texture->image->height;
    Point2 p[3];
    for (int k = 0; k < 3; ++k) {
        const TexCoord uv = uvOf(scene, m.emissive, scene.triangles[t].v[k]);
        p[k] = {double(uv.s) * w, double(uv.t) * h};
    }
    // Barycentrics of a texel-space point: the inverse of p = p0 + b1 (p1 − p0) + b2 (p2 − p0).
    const double ax = p[1].x - p[0].x, ay = p[1].y - p[0].y, bx = p[2].x - p[0].x, by = p[2].y - p[0].y;
    const double det = ax * by - ay * bx;
    auto radianceAt = [&](const Point2& q) { return emissionAt(m, scene.textures.get(), {float(q.x / w), float(q.y / h)}); };
    double lowX = std::min({p[0].x, p[1].x, p[2].x}), highX = std::max({p[0].x, p[1].x, p[2].x});
    double lowY = std::min({p[0].y, p[1].y, p[2].y}), highY = std::max({p[0].y, p[1].y, p[2].y});
    const bool finite = std::isfinite(det) && std::isfinite(lowX + highX + lowY + highY);
    const double cells = finite ? (std::floor(highX) - std::floor(lowX) + 1) * (std::floor(highY) - std::floor(lowY) + 1) : 0;
    // A triangle without area in texture space (all its corners on one texel, or a line), or
    // with coordinates beyond reason: one piece, at its centroid's texel.
    if (!finite || !(std::abs(det) > 1e-12) || cells <= 1) {
        EmissionPiece whole;
        whole.triangle = t;
        whole.corner = {{{0, 0}, {1, 0}, {0, 1}}};
        whole.radiance = radianceAt({(p[0].x + p[1].x + p[2].x) / 3, (p[0].y + p[1].y + p[2].y) / 3});
        if (maxComponent(whole.radiance) > 0) pieces.push_back(whole);
        return pieces;
    }
    // Cells of `block` texels a side, so that at most about kMostCells are visited.
    const double block = std::max(1.0, std::ceil(std::sqrt(cells / double(kMostCells))));
    const double uvArea = 0.5 * std::abs(det);
    const std::vector<Point2> triangle = {p[0], p[1], p[2]};
    for (double y0 = std::floor(lowY / block) * block; y0 < highY; y0 += block) {
        const std::vector<Point2> row = clipped(clipped(triangle, false, y0, true), false, y0 + block, false);
        if (row.size() < 3) continue;
        for (double x0 = std::floor(lowX / block) * block; x0 < highX; x0 += block) {
            const std::vector<Point2> cell = clipped(clipped(row, true, x0, true), true, x0 + block, false);
            if (cell.size() < 3) continue;
            const double area = polygonArea(cell);
            if (!(area > 0)) continue;
            Point2 centroid{0, 0};
            for (const Point2& q : cell) centroid.x += q.x / double(cell.size()), centroid.y += q.y / double(cell.size());
            const Vec3f radiance = radianceAt(centroid);
            if (!(maxComponent(radiance) > 0)) continue;
            auto bary = [&](const Point2& q) {
                const double dx = q.x - p[0].x, dy = q.y - p[0].y;
                return std::array<float, 2>{float((dx * by - dy * bx) / det), float((ax * dy - ay * dx) / det)};
            };
            // The convex piece as a fan of triangles, each an emitter of the piece's radiance.
            for (size_t i = 1; i + 1 < cell.size(); ++i) {
                EmissionPiece piece;
                piece.triangle = t;
                piece.corner = {bary(cell[0]), bary(cell[i]), bary(cell[i + 1])};
                piece.areaShare = float(polygonArea({cell[0], cell[i], cell[i + 1]}) / uvArea);
                piece.radiance = radiance;
                if (piece.areaShare > 0) pieces.push_back(piece);
            }
        }
    }
    return pieces;
}

}  // namespace qsgi
