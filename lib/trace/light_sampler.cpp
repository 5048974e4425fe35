#include "trace/light_sampler.h"

#include <algorithm>

#include "trace/sampling.h"

namespace qsgi {

LightSampler::LightSampler(const Scene& scene, uint64_t photonCount, float rayEpsilon)
    : scene_(scene), rayEpsilon_(rayEpsilon) {
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
        // One-sided Lambertian emitter: exitance π L_e over the area.
        emitters_.push_back({Emitter::Triangle, t, m.emission * (kPi * area), Vec3f(0.0f)});
    }
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
    for (Emitter& e : emitters_) {
        const double p = luminance(e.power) / sum;
        e.photonPower = e.power * float(1.0 / (double(photonCount) * p));
        maxPhotonPower_ = std::max(maxPhotonPower_, maxComponent(e.photonPower));
    }
}

PhotonEmission LightSampler::sample(const PhotonRandom& rng) const {
    using namespace rng_dim;
    const double target = double(rng.uniform(0, kLightChoice)) * cdf_.back();
    size_t i = size_t(std::upper_bound(cdf_.begin(), cdf_.end(), target) - cdf_.begin());
    i = std::min(i, emitters_.size() - 1);
    const Emitter& e = emitters_[i];
    const float u0 = rng.uniform(0, kEmitPosition0), u1 = rng.uniform(0, kEmitPosition1);
    const float v0 = rng.uniform(0, kEmitDirection0), v1 = rng.uniform(0, kEmitDirection1);

    PhotonEmission out;
    out.power = e.photonPower;
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
        case Emitter::Triangle: {
            const Triangle& tri = scene_.triangles[e.index];
            float b1, b2;
            uniformTriangle(u0, u1, b1, b2);
            const Vec3f& a = scene_.positions[tri.v[0]];
            const Vec3f& b = scene_.positions[tri.v[1]];
            const Vec3f& c = scene_.positions[tri.v[2]];
            const Vec3f n = scene_.geometricNormal(e.index);
            out.origin = a * (1 - b1 - b2) + b * b1 + c * b2 + n * rayEpsilon_;
            out.direction = cosineHemisphere(n, v0, v1);
            break;
        }
    }
    return out;
}

}  // namespace qsgi
