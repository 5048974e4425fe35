#include "estimate/direct_light.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include "estimate/vertex_samples.h"
#include "scene/emission_pieces.h"
#include "trace/sampling.h"
#include "util/stopwatch.h"

namespace qsgi {

void DirectLight::readEmitters(const Scene& scene) {
    const Stopwatch clock;
    emitters_.clear();
    std::vector<LightBounds> bounds;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const Material& m = scene.materials[scene.triangleMaterial[t]];
        const float area = scene.triangleArea(t);
        if (!m.isEmissive() || !(area > 0)) continue;
        const Triangle& tri = scene.triangles[t];
        const std::array<Vec3d, 3> corners = {Vec3d(scene.positions[tri.v[0]]), Vec3d(scene.positions[tri.v[1]]),
                                              Vec3d(scene.positions[tri.v[2]])};
        const Vec3d normal(scene.geometricNormal(t));
        // A textured emitter piece by piece (emission_pieces.h), each an emitter of its own.
        for (const EmissionPiece& piece : emissionPieces(scene, t)) {
            const float pieceArea = area * piece.areaShare;
            // Its intensity along its normal, L_e A, by which the tree weighs it (light_tree.h).
            const double intensity = double(luminance(piece.radiance)) * double(pieceArea);
            if (!(intensity > 0)) continue;
            std::array<Vec3d, 3> at = corners;
            const bool whole = piece.areaShare == 1 && piece.corner[1][0] == 1 && piece.corner[2][1] == 1;
            if (!whole)
                for (size_t k = 0; k < 3; ++k) {
                    const double b1 = piece.corner[k][0], b2 = piece.corner[k][1];
                    at[k] = corners[0] * (1 - b1 - b2) + corners[1] * b1 + corners[2] * b2;
                }
            emitters_.push_back({Emitter::Kind::Triangle, piece.radiance, pieceArea, at, normal});
            const Vec3f box[3] = {Vec3f(at[0]), Vec3f(at[1]), Vec3f(at[2])};
            bounds.push_back(LightBounds::triangle(box, normal, intensity));
        }
    }
    size_t pointAndSpot = 0;
    for (const PunctualLight& l : scene.lights) pointAndSpot += l.type != LightType::Directional;
    lightsSampled_ = samplesLights(pointAndSpot, samples_);
    // Directional lights past S: S samples of their own, each chosen by its irradiance E.
    directionalCdf_.clear();
    directional_.clear();
    if (samplesLights(scene.lights.size() - pointAndSpot, samples_)) {
        double running = 0;
        for (uint32_t i = 0; i < scene.lights.size(); ++i) {
            const PunctualLight& l = scene.lights[i];
            const double e = double(luminance(l.intensity));
            if (l.type != LightType::Directional || !(e > 0)) continue;
            running += e;
            directional_.push_back(i);
            directionalCdf_.push_back(running);
        }
    }
    if (lightsSampled_)
        for (const PunctualLight& l : scene.lights) {
            if (l.type == LightType::Directional) continue;
            const Vec3d at(l.position);
            // Weighed by its intensity I (light_tree.h): a narrow spot lights what it reaches as
            // strongly as a point light of the same I.
            const bool spot = l.type == LightType::Spot;
            const double intensity = double(luminance(l.intensity));
            if (!(intensity > 0) || (spot && !(l.cosOuterCone < 1))) continue;
            emitters_.push_back({spot ? Emitter::Kind::Spot : Emitter::Kind::Point, l.intensity, 0.0f, {at, at, at},
                                 Vec3d(l.direction), double(l.cosOuterCone)});
            bounds.push_back(spot ? LightBounds::spot(l.position, normalize(Vec3d(l.direction)), double(l.cosOuterCone), intensity)
                                  : LightBounds::point(l.position, intensity));
        }
    tree_ = LightTree(bounds);
    // Where shadow rays can go, for raysMeeting's cull: to the tree's emitters, to the point and
    // spot lights that have a ray each, along the directional lights' directions, and toward the
    // environment anywhere above v's tangent plane.
    towardDirectional_.clear();
    ownRayLights_.clear();
    reachScale_ = 1;
    for (const PunctualLight& l : scene.lights) {
        if (l.type == LightType::Directional) {
            towardDirectional_.push_back(-Vec3d(l.direction));
            continue;
        }
        reachScale_ = std::max(reachScale_, length(Vec3d(l.position)));
        if (!lightsSampled_) ownRayLights_.push_back(Vec3d(l.position));
    }
    for (const Emitter& e : emitters_)
        for (const Vec3d& c : e.corner) reachScale_ = std::max(reachScale_, length(c));
    environmentRays_ = scene.environment && samples_ > 0;
    emittersRead_ = true;
    treeSeconds_ = clock.seconds();
}

namespace {
// Whether a segment from `start` to a point of the ball `lights` can pass through the ball `box`:
// it lies in the cone from `start` that holds `lights`, no further than its far side, and the
// box's ball meets that cone if the angle between their axes is at most the sum of their
// half-angles (compared as cosines: the sum is at most π).
bool coneMeets(const Vec3d& start, const Vec3d& lightsCentre, double lightsRadius, const Vec3d& boxCentre, double boxRadius) {
    const Vec3d towardBox = boxCentre - start, towardLights = lightsCentre - start;
    const double boxDistance = length(towardBox), lightDistance = length(towardLights);
    if (boxDistance <= boxRadius || lightDistance <= lightsRadius) return true;
    if (boxDistance - boxRadius > lightDistance + lightsRadius) return false;
    const double sinLights = lightsRadius / lightDistance, sinBox = boxRadius / boxDistance;
    const double cosSum = std::sqrt(1 - sinLights * sinLights) * std::sqrt(1 - sinBox * sinBox) - sinLights * sinBox;
    return dot(towardLights, towardBox) >= cosSum * lightDistance * boxDistance;
}
}  // namespace

bool DirectLight::mayMeet(const Vec3d& start, const Vec3d& p, const Vec3d& n, const Ball& box, std::vector<uint32_t>& stack) const {
    const Vec3d towardBox = box.centre - start;
    if (length(towardBox) <= box.radius) return true;
    // The environment's rays: anywhere above the tangent plane.
    if (environmentRays_ && dot(towardBox, n) > -box.radius) return true;
    // A directional light's ray: the half-line from the start.
    for (const Vec3d& w : towardDirectional_) {
        const double along = dot(towardBox, w);
        if (along >= -box.radius && length(towardBox - w * std::max(along, 0.0)) <= box.radius) return true;
    }
    for (const Vec3d& light : ownRayLights_)
        if (coneMeets(start, light, 0.0, box.centre, box.radius)) return true;
    // The tree's emitters: down every node a sample can reach from (p, n) (importance above 0, as
    // LightTree::sample descends) whose box's ball the box's cone meets, to a leaf or a panel.
    if (tree_.empty()) return false;
    stack.assign(1, 0);
    while (!stack.empty()) {
        const LightTree::Node& node = tree_.node(stack.back());
        const uint32_t index = stack.back();
        stack.pop_back();
        // sample() never asks the root's importance (a single emitter, or a panel at the root, is
        // chosen whatever it is): nor does the cull.
        if (index != 0 && !(node.bounds.importance(p, n) > 0)) continue;
        const Vec3d lower(node.bounds.box.lower), upper(node.bounds.box.upper);
        if (!coneMeets(start, (lower + upper) * 0.5, 0.5 * length(upper - lower), box.centre, box.radius)) continue;
        if (node.leaf() || node.panel) return true;
        stack.push_back(index + 1);
        stack.push_back(uint32_t(node.second));
    }
    return false;
}

template <class Visit>
void DirectLight::forEachShadowRay(const Scene& scene, const VertexStarts& starts, uint32_t v, Visit&& visit) const {
    // The irradiance is v's own: distance and cosines from v itself. Only the shadow ray leaves
    // from s_v, a float error off v (VertexStarts).
    const Vec3d p(scene.positions[v]);
    const Vec3d start(starts.point(v));
    const Vec3d n(starts.normal(v));
    constexpr float kInfinity = std::numeric_limits<float>::infinity();
    // The shadow segment from s_v to `target`: its direction and length.
    auto shadowTo = [&](const Vec3d& target, Vec3f& direction, float& tfar) {
        const Vec3d d = target - start;
        const double len = length(d);
        if (!(len > 0)) return false;
        direction = Vec3f(d / len);
        tfar = float(len);
        return true;
    };
    Vec3f direction;
    float tfar;
    for (const PunctualLight& l : scene.lights) {
        if (l.type == LightType::Directional) {
            if (!directionalCdf_.empty()) continue;  // sampled below
            const Vec3d w = -Vec3d(l.direction);
            const double cosV = dot(n, w);
            if (cosV > 0) visit(Vec3f(w), kInfinity, Vec3d(l.intensity) * cosV);
            continue;
        }
        if (lightsSampled_) continue;  // through the tree below
        const Vec3d d = Vec3d(l.position) - p;
        const double d2 = dot(d, d);
        if (!(d2 > 0)) continue;
        const Vec3d w = d / std::sqrt(d2);
        const double cosV = dot(n, w);
        if (!(cosV > 0)) continue;
        // A spot light sends its intensity inside the outer cone only (its photons likewise).
        if (l.type == LightType::Spot && dot(-w, Vec3d(l.direction)) < double(l.cosOuterCone)) continue;
        if (shadowTo(Vec3d(l.position), direction, tfar)) visit(direction, tfar, Vec3d(l.intensity) * (cosV / d2));
    }
    if (scene.environment && samples_ > 0) environmentRays(*scene.environment, n, v, visit);
    if (samples_ == 0) return;
    const VertexSamples numbers(seed_, v, VertexStream::Direct);
    if (!directionalCdf_.empty()) {
        // E cosθ_v / P(light) with P = E over all the directional lights' E (luminance).
        const VertexSamples::Dimension pick = numbers.dimension(4);
        const double total = directionalCdf_.back();
        for (uint32_t i = 0; i < samples_; ++i) {
            const double target = double(pick.uniform(i)) * total;
            const size_t k = std::min(size_t(std::upper_bound(directionalCdf_.begin(), directionalCdf_.end(), target) -
                                             directionalCdf_.begin()),
                                      directional_.size() - 1);
            const PunctualLight& l = scene.lights[directional_[k]];
            const Vec3d w = -Vec3d(l.direction);
            const double cosV = dot(n, w);
            const double probability = double(luminance(l.intensity)) / total;
            if (cosV > 0) visit(Vec3f(w), kInfinity, Vec3d(l.intensity) * (cosV / probability / double(samples_)));
        }
    }
    if (tree_.empty()) return;
    const VertexSamples::Dimension choose = numbers.dimension(0), fine = numbers.dimension(3);
    const double perSample = 1.0 / double(samples_);
    for (uint32_t i = 0; i < samples_; ++i) {
        // Dimension 0 descends the tree, stratified; dimension 3 adds the bits below its 24, so
        // that an emitter whose probability is below 2^-24 can still be drawn.
        const double u = double(choose.uniform(i)) + double(fine.uniform(i)) * 0x1p-24;
        LightTree::Choice choice;
        if (!tree_.sample(p, n, u, choice)) continue;
        const Emitter& emitter = emitters_[choice.emitter];
        if (emitter.kind != Emitter::Kind::Triangle) {
            // A point or spot light: I cosθ_v / (d² P), as its exact ray would bring, over P.
            const Vec3d d = emitter.corner[0] - p;
            const double d2 = dot(d, d);
            if (!(d2 > 0)) continue;
            const Vec3d w = d / std::sqrt(d2);
            const double cosV = dot(n, w);
            if (!(cosV > 0)) continue;
            if (emitter.kind == Emitter::Kind::Spot && dot(-w, emitter.normal) < emitter.cosOuter) continue;
            if (shadowTo(emitter.corner[0], direction, tfar))
                visit(direction, tfar, Vec3d(emitter.radiance) * (cosV / d2 / choice.probability * perSample));
            continue;
        }
        float b1, b2;
        uniformTriangle(numbers.uniform(i, 1), numbers.uniform(i, 2), b1, b2);
        const Vec3d x = emitter.corner[0] * double(1 - b1 - b2) + emitter.corner[1] * double(b1) + emitter.corner[2] * double(b2);
        const Vec3d d = x - p;
        const double d2 = dot(d, d);
        if (!(d2 > 0)) continue;
        const Vec3d w = d / std::sqrt(d2);
        const double cosV = dot(n, w);
        const double cosE = -dot(emitter.normal, w);
        if (!(cosV > 0) || !(cosE > 0)) continue;
        // L_e cosθ_v cosθ_e / (d² p), p = P(emitter at v) / area.
        const double weight = cosV * cosE / d2 * double(emitter.area) / choice.probability * perSample;
        if (shadowTo(x, direction, tfar)) visit(direction, tfar, Vec3d(emitter.radiance) * weight);
    }
}

template <class Visit>
void DirectLight::environmentRays(const EnvironmentLight& environment, const Vec3d& n, uint32_t v, Visit&& visit) const {
    constexpr float kInfinity = std::numeric_limits<float>::infinity();
    const VertexSamples numbers(seed_, v, VertexStream::Environment);
    const Vec3f normal(n);
    const double perSample = 1.0 / double(samples_);
    if (environment.isUniform()) {
        // Cosine-distributed rays: L cosθ / (cosθ / π) = π L each, so an unshadowed vertex gets
        // π L exactly, whatever the sample count.
        const Vec3d each = Vec3d(environment.radiance(normal)) * (M_PI * perSample);
        for (uint32_t i = 0; i < samples_; ++i) visit(cosineHemisphere(normal, numbers.uniform(i, 0), numbers.uniform(i, 1)), kInfinity, each);
        return;
    }
    // A map: S cosine-distributed rays and S drawn from the map, each weighted by the balance
    // heuristic, L cosθ / (p_cos + p_map) / S (Veach's one-sample-per-technique MIS). Cosine rays
    // find a broad sky, map rays a small bright sun; neither alone does both.
    for (uint32_t i = 0; i < samples_; ++i) {
        const Vec3f w = cosineHemisphere(normal, numbers.uniform(i, 0), numbers.uniform(i, 1));
        const double cosV = dot(n, Vec3d(w));
        if (!(cosV > 0)) continue;
        const double weight = cosV / (cosV / M_PI + environment.pdf(w)) * perSample;
        visit(w, kInfinity, Vec3d(environment.radiance(w)) * weight);
    }
    for (uint32_t i = 0; i < samples_; ++i) {
        const EnvironmentLight::DirectionSample d = environment.sample(numbers.uniform(i, 2), numbers.uniform(i, 3));
        const double cosV = dot(n, Vec3d(d.towardSky));
        if (!(cosV > 0)) continue;
        const double weight = cosV / (cosV / M_PI + d.pdf) * perSample;
        visit(d.towardSky, kInfinity, Vec3d(d.radiance) * weight);
    }
}

Vec3f DirectLight::vertexIrradiance(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, uint32_t v,
                                    uint64_t& rays) const {
    if (scene.vertexHidden[v]) return Vec3f(0.0f);
    const Vec3f origin = starts.point(v);
    Vec3d sum(0.0);
    forEachShadowRay(scene, starts, v, [&](const Vec3f& w, float tfar, const Vec3d& irradiance) {
        // From t = 0 (s_v lies a float error off v's own surface; a surface beside v lies as
        // near, nearer than a ray epsilon). Stop short of the light's own surface: an
        // emissive triangle does not shadow itself.
        const float end = std::isinf(tfar) ? tfar : tfar * (1 - 1e-5f) - bvh.rayEpsilon();
        if (end > 0) {
            ++rays;
            // Through panes (KHR_materials_transmission) and BLEND surfaces, what they let through.
            if (bvh.passesShares()) {
                sum += irradiance * Vec3d(bvh.transmittance(origin, w, 0.0f, end));
                return;
            }
            if (bvh.occluded(origin, w, 0.0f, end)) return;
        }
        sum += irradiance;
    });
    return Vec3f(sum);
}

void DirectLight::computeAll(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, WorkCounter* progress,
                             const std::vector<uint8_t>* dark) {
    if (!emittersRead_) readEmitters(scene);
    irradiance_.assign(scene.vertexCount(), Vec3f(0.0f));
    if (progress) progress->setTotal(scene.vertexCount());
    std::atomic<uint64_t> rays{0};
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(scene.vertexCount()), 64), [&](const tbb::blocked_range<uint32_t>& r) {
        uint64_t cast = 0;
        for (uint32_t v = r.begin(); v != r.end(); ++v)
            irradiance_[v] = dark && (*dark)[v] ? Vec3f(0.0f) : vertexIrradiance(scene, bvh, starts, v, cast);
        rays += cast;
        if (progress) progress->add(r.size());
    });
    raysCast_ = rays.load();
}

void DirectLight::recompute(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                            const std::vector<uint32_t>& vertices, const std::vector<uint8_t>* dark) {
    irradiance_.resize(scene.vertexCount(), Vec3f(0.0f));
    std::atomic<uint64_t> rays{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
        uint64_t cast = 0;
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const uint32_t v = vertices[i];
            irradiance_[v] = dark && (*dark)[v] ? Vec3f(0.0f) : vertexIrradiance(scene, bvh, starts, v, cast);
        }
        rays += cast;
    });
    raysCast_ = rays.load();
}

std::vector<uint32_t> DirectLight::raysMeeting(const Scene& scene, const VertexStarts& starts, const std::vector<Bounds3f>& boxes,
                                               ShadowCull cull, uint64_t* derived) const {
    std::vector<uint8_t> meets(scene.vertexCount(), 0);
    if (boxes.empty()) return {};
    // Each box's ball, padded far beyond a shadow ray's rounding (its float direction and length
    // are a few ulps off the double segment, over at most the scene's and the lights' reach): no
    // ray the exact test would take is culled.
    const Bounds3f sceneBounds = scene.bounds();
    const double sceneScale = std::max(length(Vec3d(sceneBounds.lower)), length(Vec3d(sceneBounds.upper)));
    std::vector<Ball> balls;
    for (const Bounds3f& box : boxes) {
        const Vec3d lower(box.lower), upper(box.upper);
        const double scale = std::max({length(lower), length(upper), reachScale_, sceneScale});
        balls.push_back({(lower + upper) * 0.5, 0.5 * length(upper - lower) + 1e-5 * scale});
    }
    std::atomic<uint64_t> looked{0};
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(scene.vertexCount()), 64), [&](const tbb::blocked_range<uint32_t>& r) {
        uint64_t count = 0;
        std::vector<uint32_t> stack;
        for (uint32_t v = r.begin(); v != r.end(); ++v) {
            const Vec3f origin = starts.point(v);
            if (cull == ShadowCull::ByCone && std::none_of(balls.begin(), balls.end(), [&](const Ball& b) {
                    return mayMeet(Vec3d(origin), Vec3d(scene.positions[v]), Vec3d(starts.normal(v)), b, stack);
                }))
                continue;
            ++count;
            bool hit = false;
            forEachShadowRay(scene, starts, v, [&](const Vec3f& w, float tfar, const Vec3d&) {
                for (const Bounds3f& box : boxes) {
                    if (hit) return;
                    double t0 = 0, t1 = double(tfar);
                    hit = box.clip(origin, w, t0, t1);
                }
            });
            meets[v] = hit;
        }
        looked += count;
    });
    if (derived) *derived = looked.load();
    std::vector<uint32_t> out;
    for (uint32_t v = 0; v < scene.vertexCount(); ++v)
        if (meets[v]) out.push_back(v);
    return out;
}

}  // namespace qsgi
