#include "scene/triangle_grid.h"

#include <algorithm>
#include <cmath>

namespace qsgi {

TriangleGrid::TriangleGrid(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles, float reach,
                           const std::vector<uint8_t>& only) {
    auto listed = [&](uint32_t t) { return only.empty() || only[t]; };
    double meanSize = 0;
    size_t count = 0;
    for (uint32_t t = 0; t < triangles.size(); ++t) {
        if (!listed(t)) continue;
        Bounds3f b;
        for (uint32_t v : triangles[t].v) b.extend(positions[v]);
        bounds_.extend(b);
        meanSize += double(maxComponent(b.diagonal()));
        ++count;
    }
    if (count == 0) return;
    bounds_ = bounds_.expanded(reach);
    meanSize /= double(count);
    const double extent = std::max(double(maxComponent(bounds_.diagonal())), 1e-30);
    cell_ = std::max({meanSize, double(reach), extent / 1024.0});
    auto cellOf = [&](double x, int axis) { return int64_t(std::floor((x - double(bounds_.lower[axis])) / cell_)); };
    for (uint32_t t = 0; t < triangles.size(); ++t) {
        if (!listed(t)) continue;
        Bounds3f b;
        for (uint32_t v : triangles[t].v) b.extend(positions[v]);
        b = b.expanded(reach);
        const int64_t x0 = cellOf(b.lower.x, 0), x1 = cellOf(b.upper.x, 0), y0 = cellOf(b.lower.y, 1), y1 = cellOf(b.upper.y, 1),
                      z0 = cellOf(b.lower.z, 2), z1 = cellOf(b.upper.z, 2);
        if (double(x1 - x0 + 1) * double(y1 - y0 + 1) * double(z1 - z0 + 1) > double(kMostCells)) {
            large_.push_back(t);
            continue;
        }
        for (int64_t x = x0; x <= x1; ++x)
            for (int64_t y = y0; y <= y1; ++y)
                for (int64_t z = z0; z <= z1; ++z)
                    cells_[uint64_t(x & 0x1FFFFF) << 42 | uint64_t(y & 0x1FFFFF) << 21 | uint64_t(z & 0x1FFFFF)].push_back(t);
    }
}

bool TriangleGrid::inside(const Vec3d& p) const {
    // Written so that NaN is outside.
    return p.x >= bounds_.lower.x && p.x <= bounds_.upper.x && p.y >= bounds_.lower.y && p.y <= bounds_.upper.y &&
           p.z >= bounds_.lower.z && p.z <= bounds_.upper.z;
}

uint64_t TriangleGrid::key(const Vec3d& p) const {
    auto cellOf = [&](double x, int axis) { return int64_t(std::floor((x - double(bounds_.lower[axis])) / cell_)); };
    return uint64_t(cellOf(p.x, 0) & 0x1FFFFF) << 42 | uint64_t(cellOf(p.y, 1) & 0x1FFFFF) << 21 | uint64_t(cellOf(p.z, 2) & 0x1FFFFF);
}

double squaredDistanceToTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const Vec3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    auto d2to = [&](const Vec3d& q) { return dot(p - q, p - q); };
    if (d1 <= 0 && d2 <= 0) return d2to(a);
    const Vec3d bp = p - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return d2to(b);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return d2to(a + ab * (d1 / (d1 - d3)));
    const Vec3d cp = p - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return d2to(c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return d2to(a + ac * (d2 / (d2 - d6)));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return d2to(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    const double denom = va + vb + vc;
    if (!(denom != 0)) return d2to(a);
    return d2to(a + ab * (vb / denom) + ac * (vc / denom));
}

}  // namespace qsgi
