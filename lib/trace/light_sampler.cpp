#include "trace/light_sampler.h"

#include <algorithm>
#include <cassert>

#include "trace/sampling.h"
#include "util/stopwatch.h"

namespace qsgi {

namespace {

// Projection maps have 2^8 × 2^8 cells: around a far model's silhouette the kept cells that
// reach nothing are a few per cent of the kept ones (FlightHelmet: 5 %). A map costs about
// 0.25 s per 100,000 triangles on two cores, once per run.
constexpr int kMapDepth = 8;

// Every aimed light's map together holds at most what 64 full maps do: set-up time and memory
// then stop growing with the light count (10,000 lights at 10 ms each took 100 s; issue 23). Past
// 64 lights each map is a level coarser per factor 4: 10,000 lights get 2^4 × 2^4 cells each.
// A coarser map is as unbiased (it is conservative at any depth) and aims a little less tightly,
// which matters less as each light's share of the photons shrinks.
constexpr double kMapCellBudget = 64.0 * double(1 << (2 * kMapDepth));

int mapDepthFor(size_t aimedLights) {
    int depth = kMapDepth;
    while (depth > 2 && double(aimedLights) * double(uint64_t(1) << (2 * depth)) > kMapCellBudget) --depth;
    return depth;
}

}  // namespace

LightSampler::LightSampler(const Scene& scene, uint64_t photonCount, float rayEpsilon, const EmissionAim& aim,
                           std::optional<uint64_t> dealSeed, const SceneBvh* probes)
    : scene_(scene), rayEpsilon_(rayEpsilon), probes_(probes) {
    const Bounds3f b = scene.animationBounds;
    boundsCentre_ = b.center();
    boundsRadius_ = std::max(0.5f * b.extent(), 1e-6f);

    for (uint32_t i = 0; i < scene.lights.size(); ++i) {
        const PunctualLight& l = scene.lights[i];
        Emitter e{Emitter::Point, i, Vec3f(0.0f), Vec3f(0.0f)};
        switch (l.type) {
            case LightType::Point: e.power = l.intensity * (4 * kPi); break;
            case LightType::Spot:
                e.kind = Emitter::Spot;
                e.power = l.intensity * (2 * kPi * (1 - l.cosOuterCone));
                break;
            case LightType::Directional:
                // Irradiance over a disc that covers the scene's bounding sphere.
                e.kind = Emitter::Directional;
                e.power = l.intensity * (kPi * boundsRadius_ * boundsRadius_);
                break;
        }
        emitters_.push_back(e);
    }
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const Material& m = scene.materials[scene.triangleMaterial[t]];
        const float area = scene.triangleArea(t);
        if (!m.isEmissive() || !(area > 0)) continue;
        // One-sided Lambertian emitter: exitance π L_e over the area; a textured one piece by
        // piece, each its own emitter (emission_pieces.h).
        for (const EmissionPiece& piece : emissionPieces(scene, t)) {
            const bool whole = piece.areaShare == 1 && piece.corner[1][0] == 1 && piece.corner[2][1] == 1;
            const int32_t index = whole ? -1 : int32_t(pieces_.size());
            if (!whole) pieces_.push_back(piece);
            emitters_.push_back({Emitter::Triangle, t, piece.radiance * (kPi * (area * piece.areaShare)), Vec3f(0.0f), -1,
                                 scene.geometricNormal(t), index});
        }
    }
    if (scene.environment) {
        // Through the disc of radius R facing each direction: π R² ∫ L dω.
        const Vec3d power = scene.environment->integral() * (M_PI * double(boundsRadius_) * double(boundsRadius_));
        emitters_.push_back({Emitter::Environment, 0, Vec3f(power), Vec3f(0.0f)});
    }
    // Emissive triangles and the environment are never aimed, nor a light whose share of the
    // photons is below kProbeRays: its map, or even its probes, would cost more rays than all its
    // photons (a million lights under 10^6 photons get about one each).
    double allPower = 0;
    for (const Emitter& e : emitters_) allPower += luminance(e.power);
    auto aimable = [&](const Emitter& e) {
        return e.kind != Emitter::Triangle && e.kind != Emitter::Environment &&
               double(photonCount) * (double(luminance(e.power)) / allPower) >= double(kProbeRays);
    };
    size_t aimedLights = 0;
    for (const Emitter& e : emitters_) aimedLights += aim.enabled && aimable(e);
    mapDepth_ = mapDepthFor(aimedLights);
    const Stopwatch aimClock;
    double unaimed = 0;
    for (Emitter& e : emitters_) {
        if (!aimable(e) || !aim.enabled) {
            unaimed += luminance(e.power);
            continue;
        }
        // Unaimed, a directional light crosses the disc around the scene (padded by the margin).
        const double padded = double(boundsRadius_) + double(aim.margin);
        unaimed += e.kind == Emitter::Directional
                       ? double(luminance(scene.lights[e.index].intensity)) * M_PI * padded * padded
                       : double(luminance(e.power));
        aimLight(e, aim);
    }
    aimSeconds_ = aimClock.seconds();
    // Drop emitters that would never be chosen.
    emitters_.erase(std::remove_if(emitters_.begin(), emitters_.end(),
                                   [](const Emitter& e) { return !(luminance(e.power) > 0); }),
                    emitters_.end());
    double sum = 0;
    for (const Emitter& e : emitters_) {
        sum += luminance(e.power);
        cdf_.push_back(sum);
        totalPower_ += e.power;
    }
    emittedFraction_ = unaimed > 0 ? std::min(1.0, sum / unaimed) : 1.0;
    for (Emitter& e : emitters_) {
        const double p = luminance(e.power) / sum;
        e.photonPower = e.power * float(1.0 / (double(photonCount) * p));
        // An environment photon's power has the luminance of photonPower and the colour of its
        // pixel (sample()), so its largest component is at most the map's largest chroma times
        // that luminance (a little above it, for the float roundings in between).
        const float largest = e.kind == Emitter::Environment
                                  ? float(scene.environment->largestChroma() * double(luminance(e.photonPower)) * (1 + 1e-6))
                                  : maxComponent(e.photonPower);
        maxPhotonPower_ = std::max(maxPhotonPower_, largest);
    }
    if (dealSeed && !emitters_.empty()) {
        const double offset = double(mix64(*dealSeed ^ 0xDEA1DEA1DEA1ull) >> 11) * 0x1p-53;
        firstPhoton_.resize(emitters_.size() + 1);
        firstPhoton_[0] = 0;
        for (size_t i = 1; i < emitters_.size(); ++i) {
            const double share = cdf_[i - 1] / sum;
            const uint64_t first = uint64_t(std::floor(double(photonCount) * share + offset));
            firstPhoton_[i] = std::clamp(first, firstPhoton_[i - 1], photonCount);
        }
        firstPhoton_.back() = photonCount;
    }
}

LightSampler::Deal LightSampler::dealt(uint64_t photon) const {
    assert(!firstPhoton_.empty() && "dealt() needs a deal seed at construction");
    const size_t e = size_t(std::upper_bound(firstPhoton_.begin(), firstPhoton_.end() - 1, photon) - firstPhoton_.begin()) - 1;
    return {uint32_t(e), uint32_t(photon - firstPhoton_[e])};
}

size_t LightSampler::chooseEmitter(float u) const {
    const double target = double(u) * cdf_.back();
    const size_t i = size_t(std::upper_bound(cdf_.begin(), cdf_.end(), target) - cdf_.begin());
    return std::min(i, emitters_.size() - 1);
}

void LightSampler::aimLight(Emitter& e, const EmissionAim& settings) {
    const PunctualLight& l = scene_.lights[e.index];
    // Every point that counts lies within `margin` of geometry, so within `reach` of the centre.
    const double epsilon = 16.0 * double(scene_.sceneEpsilon());
    const double margin = double(settings.margin) + epsilon;
    const Vec3d centre = Vec3d(boundsCentre_);
    const double reach = double(boundsRadius_) + margin;
    Aim a;
    std::vector<Target> targets;
    if (e.kind == Emitter::Directional) {
        a.axis = normalize(Vec3d(l.direction));
        a.halfSize = reach;
        targets = mapTargets(scene_, epsilon, settings.margin, [&](const Vec3d&) { return a.axis; });
        a.map = footprintMap(centre, a.axis, a.halfSize, targets, mapDepth_);
        e.power = l.intensity * float(4 * reach * reach * a.map.keptFraction());
    } else {
        const Vec3d apex = Vec3d(l.position);
        const double distance = length(centre - apex);
        const bool outside = distance > reach;
        // The domain: the cone around the scene's sphere for a light outside it, the spot's own
        // cone if that is narrower, or every direction.
        const double cosScene = outside ? std::sqrt(std::max(0.0, 1 - (reach / distance) * (reach / distance))) : -1.0;
        const double cosSpot = e.kind == Emitter::Spot ? double(l.cosOuterCone) : -1.0;
        const Vec3d spotAxis = normalize(Vec3d(l.direction));
        if (cosSpot >= cosScene) {
            a.axis = e.kind == Emitter::Spot ? spotAxis : Vec3d(0, 0, 1);
            a.cosMax = cosSpot;
        } else {
            a.axis = (centre - apex) * (1.0 / distance);
            a.cosMax = cosScene;
            if (e.kind == Emitter::Spot) {
                a.spotAxis = spotAxis;
                a.cosSpot = cosSpot;
            }
        }
        // A light inside the scene whose probes find (almost) nothing escaping emits unaimed.
        if (!outside && probes_ && !aimPays(scene_, *probes_, apex, a.axis, a.cosMax)) return;
        targets = mapTargets(scene_, epsilon, settings.margin, [&](const Vec3d& q) { return normalize(q - apex); });
        a.map = directionMap(apex, a.axis, a.cosMax, spotAxis, a.spotAxis ? cosSpot : -1.0, targets, mapDepth_);
        // A light inside the scene whose every direction may reach something emits as unaimed.
        if (a.map.keptFraction() == 1 && !outside && !a.spotAxis) return;
        e.power = l.intensity * float(2 * M_PI * (1 - a.cosMax) * a.map.keptFraction());
    }
    orthonormalBasis(a.axis, a.t, a.b);
    e.aim = int(aims_.size());
    aims_.push_back(std::move(a));
}

bool LightSampler::aimPays(const Scene& scene, const SceneBvh& bvh, const Vec3d& apex, const Vec3d& axis, double cosMax) {
    Vec3d t, b;
    orthonormalBasis(axis, t, b);
    const Vec3f origin(apex);
    constexpr double kGoldenAngle = 2.39996322972865332;  // π (3 − √5)
    int escaped = 0;
    for (int i = 0; i < kProbeRays; ++i) {
        // Equal solid angles: cosθ evenly spaced over [cosMax, 1], the azimuth by the golden angle.
        const double cosTheta = 1 - (1 - cosMax) * (double(i) + 0.5) / kProbeRays;
        const double sinTheta = std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta));
        const Vec3f direction(coneDirection(axis, t, b, cosTheta, sinTheta, kGoldenAngle * double(i)));
        constexpr float kFar = std::numeric_limits<float>::infinity();
        if (bvh.staticOccludes(origin, direction, 0.0f, kFar) || rayMeetsAny(scene.sweptBoxes, origin, direction, kFar)) continue;
        if (++escaped * kEscapeShare >= kProbeRays) return true;
    }
    return false;
}

std::vector<Vec3f> LightSampler::lightPowers(size_t lightCount) const {
    std::vector<Vec3f> powers(lightCount, Vec3f(0.0f));
    for (const Emitter& e : emitters_)
        if (e.kind != Emitter::Triangle && e.kind != Emitter::Environment && e.index < lightCount) powers[e.index] = e.power;
    return powers;
}

Vec3f LightSampler::environmentPower() const {
    for (const Emitter& e : emitters_)
        if (e.kind == Emitter::Environment) return e.power;
    return Vec3f(0.0f);
}

Vec3f LightSampler::emissiveTrianglePower() const {
    Vec3f sum(0.0f);
    for (const Emitter& e : emitters_)
        if (e.kind == Emitter::Triangle) sum += e.power;
    return sum;
}

PhotonEmission LightSampler::sample(const PathNumbers& rng) const {
    using namespace rng_dim;
    const Emitter& e = emitters_[rng.dealt() ? rng.emitter() : chooseEmitter(rng.uniform(0, kLightChoice))];
    float u0 = rng.uniform(0, kEmitPosition0), u1 = rng.uniform(0, kEmitPosition1);
    float v0 = rng.uniform(0, kEmitDirection0), v1 = rng.uniform(0, kEmitDirection1);
    // Dealt photons take their main pair from the direction dimensions, the Sobol sequence's best
    // stratified pair: a directional light, which samples only a position, takes it for that.
    if (rng.dealt() && e.kind == Emitter::Directional) {
        std::swap(u0, v0);
        std::swap(u1, v1);
    }
    // A projection map's point from the main pair (p0, p1): random photons choose the cell with a
    // number of their own; dealt ones with the leading bits of p0, read at 32 bits (wide), the
    // rest placing the point in the cell, so cells and points within them are stratified as the
    // pair is.
    auto mapPoint = [&](const ProjectionMap& map, float p0, float p1, double& x, double& y) {
        if (rng.dealt()) map.sampleStratified(rng.wide(0, kEmitDirection0), p1, x, y);  // p0 is wide's 24-bit cut
        else map.sample(rng.uniform(0, kEmitCell), p0, p1, x, y);
    };

    PhotonEmission out;
    out.power = e.photonPower;
    if (e.aim >= 0) {
        const Aim& a = aims_[size_t(e.aim)];
        const PunctualLight& l = scene_.lights[e.index];
        double x, y;
        if (e.kind == Emitter::Directional) {
            mapPoint(a.map, u0, u1, x, y);
            const Vec3d across = a.t * ((2 * x - 1) * a.halfSize) + a.b * ((2 * y - 1) * a.halfSize);
            out.origin = Vec3f(Vec3d(boundsCentre_) + across - a.axis * (2 * a.halfSize));
            out.direction = l.direction;
            return out;
        }
        // uniformCone's parameterisation, in double: the map's cells are exact in it.
        mapPoint(a.map, v0, v1, x, y);
        const double cosTheta = 1 - x * (1 - a.cosMax), sinTheta = std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta));
        const double phi = 2 * M_PI * y;
        const Vec3d d = normalize(coneDirection(a.axis, a.t, a.b, cosTheta, sinTheta, phi));
        out.origin = l.position;
        out.direction = Vec3f(d);
        if (a.spotAxis && dot(d, *a.spotAxis) < a.cosSpot) out.power = Vec3f(0.0f);
        return out;
    }
    switch (e.kind) {
        case Emitter::Point: {
            out.origin = scene_.lights[e.index].position;
            out.direction = uniformSphere(v0, v1);
            break;
        }
        case Emitter::Spot: {
            const PunctualLight& l = scene_.lights[e.index];
            out.origin = l.position;
            out.direction = uniformCone(l.direction, l.cosOuterCone, v0, v1);
            break;
        }
        case Emitter::Directional: {
            const PunctualLight& l = scene_.lights[e.index];
            Vec3f t, b;
            orthonormalBasis(l.direction, t, b);
            float x, y;
            uniformDisc(u0, u1, x, y);
            out.origin = boundsCentre_ + (t * x + b * y) * boundsRadius_ - l.direction * (2 * boundsRadius_);
            out.direction = l.direction;
            break;
        }
        case Emitter::Environment: {
            // The direction from the main pair, the point on the disc from the other.
            const EnvironmentLight& environment = *scene_.environment;
            const EnvironmentLight::DirectionSample d = environment.sample(v0, v1);
            Vec3f t, b;
            orthonormalBasis(d.towardSky, t, b);
            float x, y;
            uniformDisc(u0, u1, x, y);
            out.origin = boundsCentre_ + (t * x + b * y) * boundsRadius_ + d.towardSky * (2 * boundsRadius_);
            out.direction = -d.towardSky;
            // L(ω) π R² / (p(ω) N P(environment)) with p = luminance(L) / ∫ luminance(L) dω: the
            // pixel's colour at the luminance every environment photon carries.
            out.power = d.radiance * float(double(luminance(e.photonPower)) / double(luminance(d.radiance)));
            break;
        }
        case Emitter::Triangle: {
            const Triangle& tri = scene_.triangles[e.index];
            float b1, b2;
            uniformTriangle(u0, u1, b1, b2);
            if (e.piece >= 0) {
                // The point within the piece, as barycentrics of its triangle.
                const auto& c = pieces_[size_t(e.piece)].corner;
                const float p1 = b1, p2 = b2, p0 = 1 - p1 - p2;
                b1 = c[0][0] * p0 + c[1][0] * p1 + c[2][0] * p2;
                b2 = c[0][1] * p0 + c[1][1] * p1 + c[2][1] * p2;
            }
            const Vec3f& a = scene_.positions[tri.v[0]];
            const Vec3f& b = scene_.positions[tri.v[1]];
            const Vec3f& c = scene_.positions[tri.v[2]];
            const Vec3f& n = e.normal;
            out.origin = a * (1 - b1 - b2) + b * b1 + c * b2 + n * rayEpsilon_;
            out.direction = cosineHemisphere(n, v0, v1);
            break;
        }
    }
    return out;
}

}  // namespace qsgi
