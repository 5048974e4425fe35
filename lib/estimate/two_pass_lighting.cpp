#include "estimate/two_pass_lighting.h"

#include <algorithm>

#include "estimate/covered_vertices.h"
#include "util/memory.h"
#include "util/stopwatch.h"

namespace qsgi {

TwoPassLighting::TwoPassLighting(const LightingSettings& settings, uint64_t seed)
    : settings_(settings),
      direct_(settings.directSamples, seed),
      gather_(settings.gathers() ? settings.gatherRays : 0, seed, settings.cachesGather() ? GatherCache::kProbeRays : 0) {
    if (settings.cachesGather()) cache_.emplace(settings.gatherCache);
}

TwoPassLighting::KeptHits TwoPassLighting::keptGatherHits(const LightingSettings& settings, size_t vertices, bool updatesFollow) {
    KeptHits kept;
    if (!settings.gathers()) return kept;
    kept.perVertex = settings.cachesGather() ? LightingSettings::kGatherProbeRays : updatesFollow ? settings.gatherRays : 0;
    kept.bytes = saturatingMultiply(vertices, kept.perVertex * sizeof(GatherHit));
    return kept;
}

size_t TwoPassLighting::stateBytes() const {
    return direct_.irradiance().capacity() * sizeof(Vec3f) + gather_.bytes() + (cache_ ? cache_->bytes() : 0);
}

uint64_t TwoPassLighting::placeRecords(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, WorkCounter* progress) {
    if (!cache_) return 0;
    cache_->select(scene, bvh, starts, gather_);
    gather_.setRecords(scene, bvh, starts, cache_->records(), progress);
    return cache_->recordCount();
}

SecondPassReport TwoPassLighting::solve(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                                        const VertexRadiosity& photons, VertexRadiosity& out, WorkCounter* progress,
                                        bool keepForUpdates) {
    SecondPassReport report;
    Stopwatch clock;
    // The gather's rays first: their cover rays tell the dark back sides, which direct light skips.
    auto direct = [&] {
        Stopwatch directClock;
        if (progress) progress->start("direct", scene.vertexCount());
        direct_.computeAll(scene, bvh, starts, progress, dark_.empty() ? nullptr : &dark_);
        report.directSeconds = directClock.seconds();
        report.shadowRays = direct_.raysCast();
    };
    dark_.clear();
    if (settings_.gathers() && !keepForUpdates && !cache_) {
        clock.restart();
        if (progress) progress->start("gathering", scene.vertexCount());
        // castAndGather keeps no hit: the rays that tell covered vertices are cast first.
        covered_ = gather_.castCovered(scene, bvh, starts);
        if (scene.backSides) dark_ = gather_.darkBackSides(scene, starts, covered_);
        double gatherSeconds = clock.seconds();
        direct();
        clock.restart();
        const FirstPassValues first = firstPass(scene, bvh, photons);
        gather_.castAndGather(scene, bvh, starts, first.view(covered_), out.irradiance, progress);
        zeroDark(out.irradiance);
        report.gatherRays = gather_.raysCast() + uint64_t(scene.vertexCount()) * gather_.coverRays();
        addDirect(scene, out);
        report.gatherSeconds = gatherSeconds + clock.seconds();
        solved_ = false;  // nothing kept to update
        return report;
    }
    double gatherSeconds = 0;
    if (settings_.gathers()) {
        clock.restart();
        if (progress) progress->start("gathering", scene.vertexCount());
        gather_.castAll(scene, bvh, starts, progress);
        report.gatherRecords = placeRecords(scene, bvh, starts, progress);
        report.gatherRays = gather_.raysCast();
        if (scene.backSides) dark_ = gather_.darkBackSides(scene, starts);
        gatherSeconds = clock.seconds();
    }
    direct();
    clock.restart();
    combine(scene, bvh, starts, photons, out);
    report.gatherSeconds = gatherSeconds + clock.seconds();
    // Without a gather nothing grows with M: the state stays for updates either way.
    solved_ = keepForUpdates || !settings_.gathers();
    if (!solved_) gather_.clear();
    return report;
}

SecondPassReport TwoPassLighting::update(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                                         const std::vector<uint32_t>& newStarts, const MovedGeometry& moved,
                                         const VertexRadiosity& photons, VertexRadiosity& out) {
    SecondPassReport report;
    Stopwatch clock;
    // A segment that grazes a mover's bounds is re-cast: the margin covers Embree's hits on the
    // bounds' faces.
    const float margin = 4 * scene.sceneEpsilon() + bvh.rayEpsilon();
    std::vector<Bounds3f> boxes;
    for (const Bounds3f& b : moved.bounds)
        if (!b.empty()) boxes.push_back(b.expanded(margin));
    // The gather first, as solve(): which back sides are dark may change with the move.
    const std::vector<uint8_t> darkBefore = dark_;
    if (settings_.gathers()) {
        gather_.resetRayCount();
        gather_.cast(scene, bvh, starts, newStarts);
        std::vector<uint8_t> skip(scene.vertexCount(), 0);
        for (uint32_t v : newStarts) skip[v] = 1;
        gather_.recastMeeting(scene, bvh, starts, boxes, skip);
        report.gatherRecords = placeRecords(scene, bvh, starts);
        report.gatherRays = gather_.raysCast();
        if (scene.backSides) dark_ = gather_.darkBackSides(scene, starts);
    }
    const double gatherSeconds = clock.seconds();
    clock.restart();
    // Lights are static (an emissive mover is refused, docs/design.md §2): the emitters read at the
    // first solve stand.
    std::vector<uint32_t> vertices = direct_.raysMeeting(scene, starts, boxes);
    vertices.insert(vertices.end(), newStarts.begin(), newStarts.end());
    for (uint32_t v = 0; v < dark_.size(); ++v)
        if ((darkBefore.empty() ? 0 : darkBefore[v]) != dark_[v]) vertices.push_back(v);
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    direct_.recompute(scene, bvh, starts, vertices, dark_.empty() ? nullptr : &dark_);
    report.directSeconds = clock.seconds();
    report.shadowRays = direct_.raysCast();
    clock.restart();
    combine(scene, bvh, starts, photons, out);
    report.gatherSeconds = gatherSeconds + clock.seconds();
    return report;
}

TwoPassLighting::FirstPassValues TwoPassLighting::firstPass(const Scene& scene, const SceneBvh& bvh, const VertexRadiosity& photons) {
    const SurfaceLookup& surfaces = bvh.surfaces();
    const std::vector<Vec3f>& direct = direct_.irradiance();
    FirstPassValues first;
    first.solved.resize(scene.vertexCount());
    const bool varies = surfaces.any();
    if (varies) {
        first.surfaces = &surfaces;
        first.solvedIrradiance.resize(scene.vertexCount());
    }
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3f arriving = scene.vertexHidden[v] ? Vec3f(0.0f) : direct[v] + photons.irradiance[v];
        first.solved[v] = scene.vertexHidden[v] ? Vec3f(0.0f) : vertexAlbedo(scene, v) * arriving;
        if (varies) first.solvedIrradiance[v] = arriving;
    }
    first.filled = first.solved;
    fillCoveredFirstPass(scene, covered_, first.filled);
    if (varies) {
        first.filledIrradiance = first.solvedIrradiance;
        fillCoveredFirstPass(scene, covered_, first.filledIrradiance);
    }
    return first;
}

void TwoPassLighting::zeroDark(std::vector<Vec3f>& gathered) const {
    // A dark back side is 0 by the cover rule, though its cover rays may meet back sides that
    // photons reached (through a tube's open ends), and the cache would interpolate it from its
    // lit neighbours.
    for (uint32_t v = 0; v < dark_.size(); ++v)
        if (dark_[v]) gathered[v] = Vec3f(0.0f);
}

void TwoPassLighting::addDirect(const Scene& scene, VertexRadiosity& out) const {
    const std::vector<Vec3f>& direct = direct_.irradiance();
    for (size_t v = 0; v < scene.vertexCount(); ++v) out.irradiance[v] = direct[v] + out.irradiance[v];
    computeRadiosity(scene, out);
}

void TwoPassLighting::combine(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const VertexRadiosity& photons,
                              VertexRadiosity& out) {
    const std::vector<Vec3f>& direct = direct_.irradiance();
    const size_t n = scene.vertexCount();
    out.irradiance.resize(n);
    if (settings_.gathers()) {
        covered_ = gather_.coveredFromKept(scene, starts);
        const FirstPassValues first = firstPass(scene, bvh, photons);
        gather_.gather(scene, first.view(covered_), out.irradiance);
        if (cache_) cache_->interpolate(out.irradiance);
        zeroDark(out.irradiance);
        addDirect(scene, out);
        return;
    }
    covered_.clear();
    for (size_t v = 0; v < n; ++v) out.irradiance[v] = direct[v] + photons.irradiance[v];
    computeRadiosity(scene, out);
}

}  // namespace qsgi
