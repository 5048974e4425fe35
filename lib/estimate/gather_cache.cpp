#include "estimate/gather_cache.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <queue>
#include <tuple>

namespace qsgi {

namespace {
// A record lights only vertices whose normal is within 30° of its own: across a sharper crease
// the gathered light is another surface's.
constexpr float kMinNormalDot = 0.8660254f;
// Cells at 2^-k of the animation's diagonal, k up to this: finer spacing asks for a record of its own.
constexpr int kFinestLevel = 40;

// The major axis of a normal and its sign (0..5): a cell holding a floor and a wall gives each a record.
int majorAxis(const Vec3f& n) {
    const float ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
    if (ax >= ay && ax >= az) return n.x < 0 ? 1 : 0;
    if (ay >= az) return n.y < 0 ? 3 : 2;
    return n.z < 0 ? 5 : 4;
}

}  // namespace

// The vertices sharing a triangle with each vertex's (welded) position, its welded twins included
// (at distance 0), each once, with the edge's length: the graph the records' light spreads over.
struct GatherCache::Adjacency {
    // Each edge is tested from both ends, in the same direction (from the smaller index), so
    // the graph stays symmetric.
    static bool seeEachOther(const SceneBvh& bvh, const VertexStarts& starts, uint32_t a, uint32_t b) {
        if (a > b) std::swap(a, b);
        const Vec3f d = starts.point(b) - starts.point(a);
        const float distance = length(d);
        if (!(distance > 0)) return true;
        return !bvh.occluded(starts.point(a), d / distance, 0.0f, distance);
    }

    std::vector<uint32_t> first;  // CSR offsets by vertex
    std::vector<uint32_t> vertex;
    std::vector<float> edge;  // its length

    Adjacency(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const MeshTopology& topology) {
        const uint32_t n = uint32_t(scene.vertexCount());
        // Only vertices of some triangle of their own take part: one welded to a mesh but used by
        // no triangle would get neighbours no list names back (it becomes a record of its own).
        std::vector<uint8_t> used(n, 0);
        for (const Triangle& t : scene.triangles)
            for (uint32_t u : t.v) used[u] = 1;
        std::vector<std::vector<uint32_t>> lists(n);
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, n, 256), [&](const tbb::blocked_range<uint32_t>& r) {
            for (uint32_t v = r.begin(); v != r.end(); ++v) {
                if (scene.vertexHidden[v] || !used[v]) continue;
                std::vector<uint32_t>& list = lists[v];
                for (const uint32_t* t = topology.trianglesBegin(v); t != topology.trianglesEnd(v); ++t)
                    for (uint32_t u : scene.triangles[*t].v)
                        if (u != v && !scene.vertexHidden[u]) list.push_back(u);
                std::sort(list.begin(), list.end());
                list.erase(std::unique(list.begin(), list.end()), list.end());
                // An edge whose start points do not see each other passes under something — a
                // partition standing across the triangle, a block's foot — and carries no light.
                list.erase(std::remove_if(list.begin(), list.end(), [&](uint32_t u) { return !seeEachOther(bvh, starts, v, u); }),
                           list.end());
            }
        });
        first.assign(n + 1, 0);
        for (uint32_t v = 0; v < n; ++v) first[v + 1] = first[v] + uint32_t(lists[v].size());
        vertex.resize(first[n]);
        edge.resize(first[n]);
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, n, 256), [&](const tbb::blocked_range<uint32_t>& r) {
            for (uint32_t v = r.begin(); v != r.end(); ++v)
                for (size_t i = 0; i < lists[v].size(); ++i) {
                    vertex[first[v] + i] = lists[v][i];
                    edge[first[v] + i] = length(scene.positions[lists[v][i]] - scene.positions[v]);
                }
        });
    }
};

float GatherCache::weight(const Label& label, const Vec3f& normal, float spacing) const {
    const float reach = std::min(reach_[label.record], spacing);
    const float closeness = (dot(normal, normal_[label.record]) - kMinNormalDot) / (1 - kMinNormalDot);
    if (!(closeness > 0)) return 0;
    if (label.distance <= 1e-6f * reach) return 1e12f * closeness;  // at the record itself
    if (!(label.distance < reach)) return 0;
    const float falloff = (reach - label.distance) / label.distance;
    return falloff * falloff * closeness;
}

void GatherCache::flood(const Adjacency& adjacency, const std::vector<uint32_t>& pieces) {
    std::vector<uint32_t> sources;
    for (uint32_t v = 0; v < record_.size(); ++v)
        if (record_[v]) sources.push_back(v);
    labels_.assign(record_.size() * size_t(kRecordsPerVertex), Label{});
    std::vector<uint8_t> settled(record_.size(), 0);
    // Light stays on its piece of surface, so each piece floods on its own, in parallel: the
    // sources grouped by piece (in vertex order within each).
    std::vector<uint32_t> bySource(sources);
    std::stable_sort(bySource.begin(), bySource.end(), [&](uint32_t a, uint32_t b) { return pieces[a] < pieces[b]; });
    std::vector<size_t> groups;
    for (size_t i = 0; i < bySource.size(); ++i)
        if (i == 0 || pieces[bySource[i]] != pieces[bySource[i - 1]]) groups.push_back(i);
    groups.push_back(bySource.size());
    tbb::parallel_for(size_t(0), groups.size() - 1, [&](size_t g) {
        // Dijkstra's order over (distance, record, vertex), a total order: each vertex settles the
        // first kRecordsPerVertex records to reach it, whatever order they were pushed in.
        struct Event {
            float distance;
            uint32_t record, vertex;
            bool operator>(const Event& o) const {
                return std::tie(distance, record, vertex) > std::tie(o.distance, o.record, o.vertex);
            }
        };
        std::priority_queue<Event, std::vector<Event>, std::greater<Event>> queue;
        auto has = [&](uint32_t v, uint32_t record) {
            for (uint32_t i = 0; i < settled[v]; ++i)
                if (labels_[size_t(v) * kRecordsPerVertex + i].record == record) return true;
            return false;
        };
        for (size_t i = groups[g]; i < groups[g + 1]; ++i) queue.push({0.0f, bySource[i], bySource[i]});
        while (!queue.empty()) {
            const Event e = queue.top();
            queue.pop();
            if (settled[e.vertex] == kRecordsPerVertex || has(e.vertex, e.record)) continue;
            // A vertex reads records no farther than its own spacing (it is that far from what
            // shapes its light): the split sphere both ways. None passes through a vertex
            // crowded by geometry — the foot of a wall or a block.
            if (e.record != e.vertex && !(e.distance < spacing_[e.vertex])) continue;
            labels_[size_t(e.vertex) * kRecordsPerVertex + settled[e.vertex]++] = Label{e.record, e.distance};
            const float reach = reach_[e.record];
            const Vec3f& normal = normal_[e.record];
            for (uint32_t i = adjacency.first[e.vertex]; i < adjacency.first[e.vertex + 1]; ++i) {
                const uint32_t u = adjacency.vertex[i];
                const float d = e.distance + adjacency.edge[i];
                if (!(d < reach) || !(d < spacing_[u]) || settled[u] == kRecordsPerVertex) continue;
                if (!(dot(normal_[u], normal) > kMinNormalDot) || has(u, e.record)) continue;
                queue.push({d, e.record, u});
            }
        }
    });
}

void GatherCache::select(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const FinalGather& rays) {
    const uint32_t n = uint32_t(scene.vertexCount());
    const uint32_t probes = rays.probeRays();
    const double diagonal = std::max(double(scene.animationBounds.extent()), 1e-30);
    const double maxSpacing = double(tolerance_) * diagonal;
    // R_v = a·H_v, H_v the harmonic mean of the probes' distances.
    spacing_.assign(n, 0.0f);
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, n, 256), [&](const tbb::blocked_range<uint32_t>& r) {
        for (uint32_t v = r.begin(); v != r.end(); ++v) {
            if (scene.vertexHidden[v]) continue;
            double inverse = 0;
            for (uint32_t j = 0; j < probes; ++j) {
                const float t = rays.hit(v, j).t;
                if (std::isfinite(t)) inverse += 1.0 / std::max(double(t), 1e-30);
            }
            const double spacing = inverse > 0 ? std::min(double(tolerance_) * probes / inverse, maxSpacing) : maxSpacing;
            spacing_[v] = float(spacing);
        }
    });
    normal_.resize(n);
    for (uint32_t v = 0; v < n; ++v) normal_[v] = starts.normal(v);

    // Each vertex asks for a record in its cell; each (level, cell, piece, axis) asked for gets
    // the asking vertex nearest the cell's centre.
    const MeshTopology topology(scene);
    const std::vector<uint32_t> pieces = topology.vertexPieces(scene.triangles);
    const Adjacency adjacency(scene, bvh, starts, topology);
    record_.assign(n, 0);
    reach_.assign(n, 0.0f);
    struct Ask {
        std::array<int64_t, 6> cell;  // level, x, y, z, piece, axis
        double offCentre;
        uint32_t vertex;
    };
    std::vector<Ask> asks;
    asks.reserve(n);
    const Vec3d lower(scene.animationBounds.lower);
    for (uint32_t v = 0; v < n; ++v) {
        if (scene.vertexHidden[v]) continue;
        const double spacing = spacing_[v];
        const double level = spacing > 0 ? std::ceil(std::log2(std::sqrt(3.0) * diagonal / spacing)) : kFinestLevel + 1;
        if (level > kFinestLevel) {
            record_[v] = 1;  // finer than any cell
            continue;
        }
        const int k = std::max(0, int(level));
        const double side = std::ldexp(diagonal, -k);
        const Vec3d cell = (Vec3d(scene.positions[v]) - lower) / side;
        const Vec3d corner(std::floor(cell.x), std::floor(cell.y), std::floor(cell.z));
        const Vec3d off = cell - corner - Vec3d(0.5);
        asks.push_back({{k, int64_t(corner.x), int64_t(corner.y), int64_t(corner.z), int64_t(pieces[v]),
                         int64_t(majorAxis(starts.normal(v)))},
                        dot(off, off),
                        v});
    }
    std::sort(asks.begin(), asks.end(), [](const Ask& a, const Ask& b) {
        return std::tie(a.cell, a.offCentre, a.vertex) < std::tie(b.cell, b.offCentre, b.vertex);
    });
    // Every asker of a cell asks at the cell's level, so the one chosen reaches (its own R, as
    // Ward's records) at least the cell's diagonal: every other asker, as the crow flies.
    for (size_t i = 0; i < asks.size();) {
        record_[asks[i].vertex] = 1;
        size_t j = i;
        while (j < asks.size() && asks[j].cell == asks[i].cell) ++j;
        i = j;
    }
    for (uint32_t v = 0; v < n; ++v)
        if (record_[v]) reach_[v] = spacing_[v];
    flood(adjacency, pieces);

    // A vertex no record reaches with any weight (across a fold, a crease, a gap) becomes one,
    // and the records flood again. A new record can fill a vertex's labels before an older one's
    // light passes through it, so the next flood can leave other vertices unreached: repeat until
    // none is (the records only grow, so this ends; two rounds almost always).
    for (;;) {
        bool added = false;
        for (uint32_t v = 0; v < n; ++v) {
            if (scene.vertexHidden[v] || record_[v]) continue;
            bool reached = false;
            forEachRecordRead(v, [&](uint32_t, double) { reached = true; });
            if (reached) continue;
            record_[v] = 1;
            reach_[v] = spacing_[v];
            added = true;
        }
        if (!added) break;
        flood(adjacency, pieces);
    }
    recordCount_ = size_t(std::count(record_.begin(), record_.end(), uint8_t(1)));
}

void GatherCache::interpolate(std::vector<Vec3f>& irradiance) const {
    const uint32_t n = uint32_t(record_.size());
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, n, 256), [&](const tbb::blocked_range<uint32_t>& r) {
        for (uint32_t v = r.begin(); v != r.end(); ++v) {
            if (record_[v]) continue;
            Vec3d sum(0.0);
            double total = 0;
            forEachRecordRead(v, [&](uint32_t record, double w) {
                sum += Vec3d(irradiance[record]) * w;
                total += w;
            });
            // Hidden vertices have no labels: 0.
            irradiance[v] = total > 0 ? Vec3f(sum / total) : Vec3f(0.0f);
        }
    });
}

Vec3f GatherCache::irradianceAt(const Scene& scene, uint32_t triangle, float b1, float b2,
                                const std::vector<Vec3f>& irradiance) const {
    const Triangle& tri = scene.triangles[triangle];
    // Barycentrics clamped to the triangle and made to sum to 1.
    float b[3] = {std::clamp(1 - b1 - b2, 0.0f, 1.0f), std::clamp(b1, 0.0f, 1.0f), std::clamp(b2, 0.0f, 1.0f)};
    const float sumB = b[0] + b[1] + b[2];
    for (float& w : b) w = sumB > 0 ? w / sumB : 1.0f / 3;
    const Vec3f p = scene.positions[tri.v[0]] * b[0] + scene.positions[tri.v[1]] * b[1] + scene.positions[tri.v[2]] * b[2];
    const Vec3f normal = normalize(normal_[tri.v[0]] * b[0] + normal_[tri.v[1]] * b[1] + normal_[tri.v[2]] * b[2]);
    const float spacing = spacing_[tri.v[0]] * b[0] + spacing_[tri.v[1]] * b[1] + spacing_[tri.v[2]] * b[2];
    // Each corner's records, weighted as at the corner but for the distance through it to p, and
    // by the corner's barycentric: at a corner exactly its own weights, and continuous across
    // edges (a corner's share fades with its barycentric).
    Vec3d sum(0.0);
    double total = 0;
    for (int c = 0; c < 3; ++c) {
        if (!(b[c] > 0)) continue;
        const uint32_t corner = tri.v[c];
        const float toCorner = length(p - scene.positions[corner]);
        // A record corner offers only itself (its value is its own gather), others what they read.
        const uint32_t offered = record_[corner] ? 1 : kRecordsPerVertex;
        for (uint32_t i = 0; i < offered; ++i) {
            const Label& label = record_[corner] ? Label{corner, 0.0f} : labels_[size_t(corner) * kRecordsPerVertex + i];
            if (label.record == UINT32_MAX) break;
            const double w = double(b[c]) * weight(Label{label.record, toCorner + label.distance}, normal, spacing);
            if (w <= 0) continue;
            sum += Vec3d(irradiance[label.record]) * w;
            total += w;
        }
    }
    if (total > 0) return Vec3f(sum / total);
    // No record reaches the point (a hidden corner, or a crease between its corners): the
    // corners' values, as a viewer would interpolate them.
    return irradiance[tri.v[0]] * b[0] + irradiance[tri.v[1]] * b[1] + irradiance[tri.v[2]] * b[2];
}

std::vector<uint32_t> GatherCache::recordsRead(uint32_t v) const {
    if (record_[v]) return {v};
    std::vector<uint32_t> read;
    forEachRecordRead(v, [&](uint32_t record, double) { read.push_back(record); });
    return read;
}

size_t GatherCache::bytes() const {
    return spacing_.capacity() * sizeof(float) + record_.capacity() + reach_.capacity() * sizeof(float) +
           normal_.capacity() * sizeof(Vec3f) + labels_.capacity() * sizeof(Label);
}

}  // namespace qsgi
