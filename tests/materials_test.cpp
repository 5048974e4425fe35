// Surfaces as the asset says (issue 57, docs/inputs.md): albedo per texel and per vertex colour,
// alpha-MASK cut-outs and BLEND, through every ray (Embree's filters) and every bounce (the photon
// records keep where a varying surface was hit). Expected values are worked out here from the
// scene's own numbers; tolerances from the statistics of each estimate.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <vector>

#include "estimate/direct_light.h"
#include "estimate/vertex_starts.h"
#include "output/ply_reader.h"
#include "output/radiosity_image.h"
#include "pipeline/frame_solver.h"
#include "scene/emission_pieces.h"
#include "scene/gltf_loader.h"
#include "scene/surface_lookup.h"
#include "test_support.h"
#include "trace/light_sampler.h"
#include "trace/photon_source.h"
#include "trace/photon_tracer.h"
#include "trace/scene_bvh.h"

using namespace qsgi;
namespace fs = std::filesystem;

namespace {

double seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double srgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// A horizontal card `height` above the floor of plateUnderSheet, facing up, textured by a
// width x height RGBA checker whose texel (x, y) is opaque where `opaque(x, y)`.
struct CardScene {
    Scene scene;
    float half;  // the card's half size
    int texels;  // per side
};

CardScene cardOverFloor(AlphaMode mode, float alpha, int texels, bool (*opaque)(int, int)) {
    CardScene c{testscenes::plateUnderSheet(1.0f, 37, 0.8f, 8, 0.5f, true, Vec3f(0.5f)), 0.8f, texels};
    Material card;
    card.albedo = Vec3f(0.5f);
    card.alpha = alpha;
    card.alphaMode = mode;
    card.doubleSided = true;
    std::vector<uint8_t> rgba;
    for (int y = 0; y < texels; ++y)
        for (int x = 0; x < texels; ++x) rgba.insert(rgba.end(), {128, 128, 128, uint8_t(opaque(x, y) ? 255 : 0)});
    const uint32_t m = testscenes::addTexturedMaterial(c.scene, card, texels, texels, rgba);
    testscenes::paintInstance(c.scene, 1, m, 0, 2, Vec3f(-c.half, 0, -c.half), 2 * c.half);
    PunctualLight sun;
    sun.type = LightType::Directional;
    sun.direction = Vec3f(0, -1, 0);
    sun.intensity = Vec3f(2.0f);
    c.scene.lights.push_back(sun);
    return c;
}

// The card's texels' grey (sRGB 128), linear.
float srgbLinear128() { return float(srgbToLinear(128 / 255.0)); }

// Calls visit(v) for each floor vertex strictly under the card (a hair inside its edge).
template <class Visit>
size_t forEachFloorVertexUnderTheCard(const CardScene& c, Visit&& visit) {
    const MeshInstance& floor = c.scene.instances[0];
    size_t under = 0;
    for (uint32_t v = floor.firstVertex; v < floor.firstVertex + floor.vertexCount; ++v) {
        const Vec3f p = c.scene.positions[v];
        if (std::abs(p.x) >= c.half - 1e-3f || std::abs(p.z) >= c.half - 1e-3f) continue;
        ++under;
        visit(v);
    }
    return under;
}

// TheMaterialsRoomAgreesWithAnIndependentPathTracer's bounds: measured relative RMS 0.0285 at
// seed 1 and 0.0273 at seed 2, so 0.0285 + 3 × 0.0012 rounded up; bias −0.0010 and −0.0008, so
// 0.0010 + 3 × 0.0002 rounded up (the reference's own noise is about 2.4 % a vertex; before issue
// 57 the room was 459 % off, 3.73 % and −1.09 % before the doubleSided card's back was lit, whose
// light the reference's two-sided card reflects to the ceiling).
constexpr double kMaterialsRoomRms = 0.033, kMaterialsRoomBias = 0.002;
// EachFeatureAgreesWithAnIndependentPathTracer's bounds (RMS, |bias|), in its table's order, by
// the same rule from (seed 1, seed 2), rounded up to the next 0.001:
//   textured floor        RMS 0.0091, 0.0085   bias +0.0002, −0.0000
//   vertex colour             0.0072, 0.0073        −0.0000, −0.0003
//   MASK card                 0.0148, 0.0148        −0.0037, −0.0035
//   the card's back sides     0.0101, 0.0102        −0.0074, −0.0071
//   BLEND card                0.0168, 0.0165        −0.0060, −0.0054
//   pane to the sky           0.1463, 0.1449        +0.0055, +0.0057  (qsgi's own noise: the sky
//                             through a small window; the open window is as far off)
//   emissive texture          0.0761, 0.0729        +0.0052, +0.0049  (the box's foot on the floor)
constexpr double kFeatureBounds[7][2] = {{0.011, 0.001}, {0.008, 0.001}, {0.015, 0.005}, {0.011, 0.009},
                                         {0.018, 0.008}, {0.151, 0.007}, {0.086, 0.007}};

bool quarterOpaque(int x, int y) { return (x + 2 * y) % 4 == 0; }  // 4 of 16 texels, one in each row
bool allOpaque(int, int) { return true; }

}  // namespace

// Inside a closed sphere (R = 1, I = 1 W/sr at the centre) whose albedo is a texture: ρ₁ on the
// half x < 0, ρ₂ on x ≥ 0 (a 2 x 1 NEAREST texture projected along x, so its seam is the plane
// x = 0, which halves the icosphere's area by its symmetry). A sphere's form factor to any patch
// is its area over 4πR², so the irradiance stays uniform however the albedo varies, and
// E = E_d / (1 − ρ̄) with ρ̄ = (ρ₁ + ρ₂)/2, the albedo's mean over the surface: what holds only if
// photons bounce with the albedo at their hit and gather rays read the albedo at theirs (a mean
// colour per material would give it too, but the per-vertex check below would not: see the
// mesh-exact formula of FinalGather.ClosedSphereTwoPassGivesTheAnalyticIrradiance, which this
// one follows with ρ̄ for ρ).
//
// Noise: a gather ray returns ρ(hit)(D + I)(hit), two values ρ₁·2 and ρ₂·2 W/m² apart by
// 2|ρ₂ − ρ₁| = 1.2, a standard deviation of 0.6 per ray; over M = 256 rays at most 0.6/16 = 0.0375
// W/m², 1.9 % of E (the scrambled Sobol directions do better). The vertices' RMS is allowed three
// times that; their mean, over n ≈ 10⁴ independent vertices, 3 × 1.9 %/√n + the photons' 0.1 %.
// Textured per vertex too: the radiosity of each vertex is its own texel's albedo × E.
TEST(Materials, AClosedSphereWithATexturedAlbedoGivesEdOverOneMinusTheMeanAlbedo) {
    const auto start = std::chrono::steady_clock::now();
    const uint8_t dark = 124, light = 231;  // sRGB bytes: ρ ≈ 0.202 and 0.799
    const double rho1 = srgbToLinear(dark / 255.0), rho2 = srgbToLinear(light / 255.0), rho = (rho1 + rho2) / 2;
    const double I = 1.0;
    Scene scene = testscenes::closedSphere(1.0f, 5, Vec3f(1.0f));
    Material textured;
    textured.albedo = Vec3f(1.0f);
    const uint32_t m = testscenes::addTexturedMaterial(scene, textured, 2, 1, {dark, dark, dark, 255, light, light, light, 255});
    // s = (x + 2)/4 lies in [1/4, 3/4]: the seam at x = 0 and no wrap-around at the poles.
    testscenes::paintInstance(scene, 0, m, 0, 1, Vec3f(-2.0f), 4.0f);
    testscenes::addPointLight(scene, Vec3f(0.0f), Vec3f(float(I)));
    const EmbreeDevice device;
    FrameSolverSettings s;
    s.estimator.kind = EstimatorKind::ImpactCount;
    s.trace = TraceSettings{300000, 5, 32, EmissionAim{}, PhotonSampling{}};
    s.lighting.direct = DirectLighting::Exact;
    s.lighting.gatherRays = 256;
    s.update.fullRecompute = true;
    FrameSolver solver(scene, device, s);
    const VertexRadiosity solution = solver.solve(scene.restPose()).radiosity;
    const std::vector<Vec3f>& E = solution.irradiance;
    const size_t n = scene.vertexCount();
    double area = 0;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) area += scene.triangleArea(t);
    const double indirect = 4 * M_PI * I * rho / ((1 - rho) * area);
    std::vector<double> D(n);
    double meanD = 0;
    for (uint32_t v = 0; v < n; ++v) {
        const Vec3d p(scene.positions[v]);
        const double d2 = dot(p, p);
        D[v] = I * dot(Vec3d(scene.normals[v]), -p / std::sqrt(d2)) / d2;
        meanD += D[v] / double(n);
    }
    double sum2 = 0, mean = 0;
    for (uint32_t v = 0; v < n; ++v) {
        const double exact = D[v] + rho * (meanD + indirect);
        const double e = double(E[v].y) / exact - 1;
        sum2 += e * e;
        mean += e / double(n);
        // The vertex's own albedo: the texel its UV falls in (NEAREST).
        const double own = scene.vertexTexCoords[0][v].s * 2 >= 1 ? rho2 : rho1;
        ASSERT_NEAR(double(solution.radiosity[v].y), own * double(E[v].y), 1e-5 * double(E[v].y))
            << "vertex " << v;
    }
    const double rms = std::sqrt(sum2 / double(n)), perVertex = 0.6 / 16 / 2;
    std::printf("textured sphere: %zu vertices, rho %.4f / %.4f (mean %.4f), E/Ed ideal %.4f; vs mesh exact: RMS %.3f %%, "
                "mean %+.3f %%; %.1f s\n",
                n, rho1, rho2, rho, 1 / (1 - rho), 100 * rms, 100 * mean, seconds(start));
    EXPECT_LT(rms, 3 * perVertex);
    EXPECT_LT(std::abs(mean), 3 * perVertex / std::sqrt(double(n)) + 0.001);
    // And not what a mean colour per material would give at the vertices: the two halves' own
    // radiosities differ by ρ₂/ρ₁ ≈ 4 (checked per vertex above).
}

// Exact direct light from a sun straight overhead through an alpha-MASK checker card (a quarter of
// its texels opaque, NEAREST): a floor vertex is lit, E = 2 W/m², exactly where the vertical
// through it meets a cut-out texel, and 0 where it meets an opaque one, so the floor's mean under
// the card is (1 − c)·E with c the card's coverage, up to which texels the floor's grid samples
// (printed). The same card OPAQUE shades the whole footprint.
TEST(Materials, AMaskCheckerCardLetsTheSunThroughItsCutOutTexelsOnly) {
    for (const AlphaMode mode : {AlphaMode::Mask, AlphaMode::Opaque}) {
        const CardScene c = cardOverFloor(mode, 1.0f, 4, quarterOpaque);
        const SecondPassRig rig(c.scene);
        DirectLight direct(4, 7);
        direct.computeAll(c.scene, rig.bvh, rig.starts);
        const MeshInstance& floor = c.scene.instances[0];
        size_t under = 0, lit = 0, checked = 0;
        for (uint32_t v = floor.firstVertex; v < floor.firstVertex + floor.vertexCount; ++v) {
            const Vec3f p = c.scene.positions[v];
            const double s = (p.x + c.half) / (2 * c.half) * c.texels, t = (p.z + c.half) / (2 * c.half) * c.texels;
            const bool inside = s > 0 && s < c.texels && t > 0 && t < c.texels;
            // A vertex within a hair of a texel's edge could fall either way: left out.
            if (std::abs(s - std::round(s)) < 1e-3 || std::abs(t - std::round(t)) < 1e-3) continue;
            ++checked;
            const bool shaded = inside && (mode == AlphaMode::Opaque || quarterOpaque(int(s), int(t)));
            const float e = direct.irradiance()[v].y;
            EXPECT_EQ(e, shaded ? 0.0f : 2.0f) << "floor vertex at (" << p.x << ", " << p.z << ")";
            if (inside) ++under, lit += e > 0;
        }
        std::printf("%s card: %zu floor vertices checked, %zu under the card, lit share %.4f (1 - coverage: %.2f)\n",
                    mode == AlphaMode::Mask ? "MASK" : "OPAQUE", checked, under, double(lit) / double(under),
                    mode == AlphaMode::Mask ? 0.75 : 0.0);
        ASSERT_GT(under, 500u);
    }
}

// BLEND of alpha α = 0.3. A shadow ray takes the share 1 − α it lets through (its expectation:
// no noise), so every floor vertex under the card gets exactly (1 − α) of the unoccluded 2 W/m².
// Photons (and gather rays) choose, each once by a hash of itself and the card's triangle: of the
// sun's photons that reach the card's footprint a share 1 − α passes, within 4 binomial σ, and a
// second trace makes the same choices (the same bits).
TEST(Materials, ABlendCardPassesItsShareOfTheSunsLight) {
    const float alpha = 0.3f;
    const CardScene c = cardOverFloor(AlphaMode::Blend, alpha, 1, allOpaque);
    const SecondPassRig rig(c.scene);
    ASSERT_TRUE(rig.bvh.passesShares());
    DirectLight direct(4, 7);
    direct.computeAll(c.scene, rig.bvh, rig.starts);
    const size_t under = forEachFloorVertexUnderTheCard(
        c, [&](uint32_t v) { EXPECT_FLOAT_EQ(direct.irradiance()[v].y, 2.0f * (1 - alpha)) << "floor vertex " << v; });
    EXPECT_GT(under, 500u);
    TraceSettings settings;
    settings.photons = 40000;
    const PhotonTracer tracer(c.scene, rig.bvh, settings);
    const RayCache cache = tracer.traceAll(), again = tracer.traceAll();
    const MeshInstance& card = c.scene.instances[1];
    size_t onCard = 0, through = 0;
    const std::vector<Segment> first = cache.decodeAll(), second = again.decodeAll();
    ASSERT_EQ(first.size(), second.size());
    for (size_t i = 0; i < first.size(); ++i) {
        const Segment& s = first[i];
        ASSERT_EQ(s.triangle, second[i].triangle);
        if (s.bounce != 0 || !s.hasImpact()) continue;
        const Vec3f p = s.impactPoint();
        if (std::abs(p.x) >= c.half || std::abs(p.z) >= c.half) continue;
        const bool card_ = s.triangle >= card.firstTriangle && s.triangle < card.firstTriangle + card.triangleCount;
        ++(card_ ? onCard : through);
    }
    const double n = double(onCard + through), share = double(through) / n, sigma = std::sqrt(alpha * (1 - alpha) / n);
    std::printf("BLEND card (alpha %.1f): %.0f photons over it, %.4f through (expected %.2f, sigma %.4f)\n", alpha, n, share,
                1 - alpha, sigma);
    ASSERT_GT(n, 1000);
    EXPECT_NEAR(share, 1 - alpha, 4 * sigma);
    // What the card reflects: its alpha share of its base colour (the rest passes).
    for (uint32_t v = card.firstVertex; v < card.firstVertex + card.vertexCount; ++v)
        EXPECT_FLOAT_EQ(vertexAlbedo(c.scene, v).y, c.scene.materials.back().albedo.y * srgbLinear128() * alpha);
}

// Photons go through the cut-outs too: of the sun's photons that reach the card's footprint, the
// share whose first impact is the floor (through a cut-out texel) rather than the card is
// 1 − c = 3/4 within 4 binomial standard deviations; and every first impact on the card lies in an
// opaque texel.
TEST(Materials, PhotonsPassThroughTheCutOutTexelsAndLandOnlyOnOpaqueOnes) {
    const CardScene c = cardOverFloor(AlphaMode::Mask, 1.0f, 4, quarterOpaque);
    const EmbreeDevice device;
    const SceneBvh bvh(device, c.scene);
    TraceSettings settings;
    settings.photons = 40000;
    const PhotonTracer tracer(c.scene, bvh, settings);
    const RayCache cache = tracer.traceAll();
    const MeshInstance& card = c.scene.instances[1];
    size_t onCard = 0, onFloor = 0;
    cache.forEachSegment([&](const Segment& s) {
        if (s.bounce != 0 || !s.hasImpact()) return;
        const Vec3f p = s.impactPoint();
        if (std::abs(p.x) >= c.half || std::abs(p.z) >= c.half) return;
        if (s.triangle >= card.firstTriangle && s.triangle < card.firstTriangle + card.triangleCount) {
            ++onCard;
            const double u = (p.x + c.half) / (2 * c.half) * c.texels, w = (p.z + c.half) / (2 * c.half) * c.texels;
            EXPECT_TRUE(quarterOpaque(int(u), int(w)) || std::abs(u - std::round(u)) < 1e-4 || std::abs(w - std::round(w)) < 1e-4)
                << "a photon landed on a cut-out texel at (" << p.x << ", " << p.z << ")";
        } else {
            ++onFloor;
        }
    });
    const double n = double(onCard + onFloor), share = double(onFloor) / n, sigma = std::sqrt(0.75 * 0.25 / n);
    std::printf("photons over the card: %.0f, through it %.4f (expected 0.75, sigma %.4f)\n", n, share, sigma);
    ASSERT_GT(n, 1000);
    EXPECT_NEAR(share, 0.75, 4 * sigma);
}

// The ray cache keeps where photons hit a textured surface, so its decoded segments carry the
// powers the tracer computed with the texel's albedo, to the bit (and a path decoded alone, too).
TEST(Materials, TheRayCacheDecodesTexturedBouncesToTheTracersBits) {
    Scene scene = testscenes::closedBox(8);
    Material m;
    const uint32_t textured = testscenes::addTexturedMaterial(
        scene, m, 3, 2, {250, 30, 30, 255, 30, 250, 30, 255, 30, 30, 250, 255, 200, 200, 200, 255, 90, 90, 90, 255, 10, 10, 10, 255},
        false);
    testscenes::paintInstance(scene, 0, textured, 0, 2, Vec3f(-1.0f), 2.0f);
    scene.vertexColours.assign(scene.vertexCount(), Rgba{1, 1, 1, 1});
    for (uint32_t v = 0; v < scene.vertexCount(); v += 3) scene.vertexColours[v] = {0.4f, 0.9f, 0.7f, 1};
    testscenes::addPointLight(scene, Vec3f(0.1f, 0.5f, -0.2f), Vec3f(5.0f));
    const EmbreeDevice device;
    const SceneBvh bvh(device, scene);
    TraceSettings settings;
    settings.photons = 5000;
    settings.maxBounces = 6;
    const PhotonTracer tracer(scene, bvh, settings);
    const RayCache cache = tracer.traceAll();
    const std::vector<Segment> decoded = cache.decodeAll();
    std::vector<Segment> traced, alone;
    size_t varying = 0;
    for (uint64_t p = 0; p < settings.photons; ++p) tracer.tracePath(p, traced);
    ASSERT_EQ(traced.size(), decoded.size());
    for (size_t i = 0; i < traced.size(); ++i) {
        const Segment &a = traced[i], &b = decoded[i];
        ASSERT_EQ(a.power.x, b.power.x) << i;
        ASSERT_EQ(a.power.y, b.power.y) << i;
        ASSERT_EQ(a.power.z, b.power.z) << i;
        ASSERT_EQ(a.triangle, b.triangle) << i;
        ASSERT_EQ(a.impactVaries, b.impactVaries) << i;
        ASSERT_EQ(a.b1, b.b1) << i;
        ASSERT_EQ(a.b2, b.b2) << i;
        varying += a.impactVaries;
    }
    cache.appendPath(1234, alone);
    std::vector<Segment> one;
    tracer.tracePath(1234, one);
    ASSERT_EQ(alone.size(), one.size());
    for (size_t i = 0; i < one.size(); ++i) ASSERT_EQ(alone[i].power.y, one[i].power.y);
    EXPECT_GT(varying, traced.size() / 10);  // the textured wall was hit, often
}

// SurfaceLookup against the rule written out: factor × texel (sRGB-decoded, NEAREST or bilinear,
// KHR_texture_transform, wrap modes) × interpolated vertex colour; MASK compares alpha with the
// cutoff; OPAQUE ignores alpha.
TEST(Materials, TheSurfaceLookupFollowsTheRuleAtEveryPoint) {
    Scene scene = testscenes::plane(1.0f, 1, Vec3f(0.5f));
    Material m;
    m.albedo = Vec3f(0.5f, 1.0f, 0.8f);
    m.alpha = 0.9f;
    m.alphaMode = AlphaMode::Mask;
    m.alphaCutoff = 0.5f;
    // 2 x 2: red opaque, green half, blue clear, white opaque.
    const uint32_t id = testscenes::addTexturedMaterial(scene, m, 2, 2,
                                                        {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0, 255, 255, 255, 255});
    testscenes::paintInstance(scene, 0, id, 0, 2, Vec3f(-1.0f), 2.0f);
    scene.vertexColours.assign(scene.vertexCount(), Rgba{1, 1, 1, 1});
    scene.vertexColours[scene.triangles[0].v[1]] = {0.0f, 0.5f, 1.0f, 1.0f};
    const SurfaceLookup lookup(scene);
    ASSERT_TRUE(lookup.any());
    ASSERT_TRUE(lookup.varies(0));
    const Triangle& t = scene.triangles[0];
    for (const auto& [b1, b2] : {std::pair{0.1f, 0.2f}, {0.6f, 0.3f}, {0.05f, 0.9f}, {0.33f, 0.33f}}) {
        const float b0 = 1 - b1 - b2;
        TexCoord uv{0, 0};
        Rgba colour{0, 0, 0, 0};
        for (int k = 0; k < 3; ++k) {
            const float w = k == 0 ? b0 : k == 1 ? b1 : b2;
            uv.s += w * scene.vertexTexCoords[0][t.v[k]].s;
            uv.t += w * scene.vertexTexCoords[0][t.v[k]].t;
            for (size_t c = 0; c < 4; ++c) colour[c] += w * scene.vertexColours[t.v[k]][c];
        }
        const int x = std::clamp(int(std::floor(uv.s * 2)), 0, 1), y = std::clamp(int(std::floor(uv.t * 2)), 0, 1);
        const uint8_t* texel = &(*scene.textures)[0].image->rgba[size_t(4 * (2 * y + x))];
        const Rgba got = lookup.baseColour(0, b1, b2);
        for (size_t c = 0; c < 3; ++c)
            EXPECT_NEAR(got[c], scene.materials[id].albedo[int(c)] * srgbToLinear(texel[c] / 255.0) * colour[c], 1e-5)
                << "channel " << c << " at " << b1 << ", " << b2;
        const double alpha = 0.9 * texel[3] / 255.0 * colour[3];
        EXPECT_NEAR(got[3], alpha, 1e-5);
        EXPECT_EQ(lookup.stops(0, b1, b2, 0.99f), alpha >= 0.5);
    }
    // Wrap modes: repeat, mirrored repeat and clamp, one texel past each edge.
    Texture tex = (*scene.textures)[0];
    const auto red = [&](float s, float u) { return tex.sample({s, u}, false)[0] > 0.5f; };
    EXPECT_TRUE(red(0.25f, 0.25f));
    EXPECT_FALSE(red(1.25f + 0.5f, 0.25f));  // repeat: (0.75, 0.25), green
    tex.wrapS = TextureWrap::MirroredRepeat;
    EXPECT_TRUE(red(1.75f, 0.25f));  // mirrored: 1.75 -> 0.25
    tex.wrapS = TextureWrap::ClampToEdge;
    EXPECT_TRUE(red(-3.0f, 0.25f));
    EXPECT_FALSE(red(3.0f, 0.25f));
    // KHR_texture_transform: an offset of half the texture moves red to where green was.
    UvTransform shift;
    shift.offset[0] = 0.5f;
    const TexCoord moved = shift.apply({0.25f, 0.25f});
    EXPECT_NEAR(moved.s, 0.75f, 1e-6);
    UvTransform turn;
    turn.rotation = float(M_PI / 2);
    const TexCoord turned = turn.apply({1.0f, 0.0f});
    EXPECT_NEAR(turned.s, 0.0f, 1e-6);  // the extension's own matrix: (1, 0) turns to (0, 1)
    EXPECT_NEAR(turned.t, 1.0f, 1e-6);
    // OPAQUE: alpha is 1 whatever the texture says, and every ray stops.
    scene.materials[id].alphaMode = AlphaMode::Opaque;
    const SurfaceLookup opaque(scene);
    EXPECT_EQ(opaque.baseColour(0, 0.6f, 0.3f)[3], 1.0f);
    EXPECT_FALSE(opaque.letsLightThrough(0));
}

// Emission per texel: a 2 m quad (3 x 3 cells, so its triangles cut across texels) whose emissive
// texture (4 x 4, NEAREST) is black but for one white texel, a 0.5 m square of it. Its emitters
// hold exactly the texel's power, π L_e · 0.25 m² (the pieces cut along the texel grid, so the
// integral is exact but for float roundings), and every photon starts inside the texel's
// footprint; the vertices' own radiance is the texel under each.
TEST(Materials, AnEmissiveTextureEmitsFromItsBrightTexelAlone) {
    Scene scene = testscenes::plane(1.0f, 3, Vec3f(0.5f));
    std::vector<uint8_t> rgba(4 * 4 * 4, 0);
    for (size_t i = 3; i < rgba.size(); i += 4) rgba[i] = 255;
    const int brightX = 2, brightY = 1;
    for (size_t c = 0; c < 3; ++c) rgba[size_t(4 * (4 * brightY + brightX)) + c] = 255;
    const uint32_t id = testscenes::addTexturedMaterial(scene, Material("screen", Vec3f(0.5f)), 4, 4, rgba);
    Material& screen = scene.materials[id];
    screen.emissive = screen.baseColour;
    screen.baseColour = TextureSlot();
    screen.emission = Vec3f(2.0f, 1.0f, 0.5f);
    testscenes::paintInstance(scene, 0, id, 0, 2, Vec3f(-1.0f), 2.0f);
    const LightSampler lights(scene, 20000, scene.sceneEpsilon());
    const Vec3f power = lights.emissiveTrianglePower();
    const double footprint = 0.5 * 0.5;
    EXPECT_NEAR(power.x, M_PI * 2.0 * footprint, 1e-5);
    EXPECT_NEAR(power.y, M_PI * 1.0 * footprint, 1e-5);
    EXPECT_NEAR(power.z, M_PI * 0.5 * footprint, 1e-5);
    const PhotonSource source(scene, 20000, 3, 1e-6f, EmissionAim{}, PhotonSampling{});
    const float x0 = -1 + 2.0f * brightX / 4, z0 = -1 + 2.0f * brightY / 4;
    for (uint64_t p = 0; p < 20000; ++p) {
        const PhotonEmission e = source.emission(p);
        ASSERT_GE(e.origin.x, x0 - 1e-5f) << p;
        ASSERT_LE(e.origin.x, x0 + 0.5f + 1e-5f) << p;
        ASSERT_GE(e.origin.z, z0 - 1e-5f) << p;
        ASSERT_LE(e.origin.z, z0 + 0.5f + 1e-5f) << p;
    }
    // A vertex's own radiance: the texel its UV falls in (NEAREST), so black but where a vertex
    // lies inside the bright texel's footprint.
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        const TexCoord uv = scene.vertexTexCoords[0][v];
        const bool bright = int(std::floor(uv.s * 4)) == brightX && int(std::floor(uv.t * 4)) == brightY;
        EXPECT_EQ(vertexEmission(scene, v).x, bright ? 2.0f : 0.0f) << "vertex " << v;
    }
}

// A thin pane (KHR_materials_transmission T = 0.6, base colour t = (0.9, 0.5, 0.3)) over the floor,
// under a sun straight overhead: the sun's shadow rays from the floor under it bring T · t of the
// unoccluded 2 W/m², exactly (one pane, one factor); of the photons that reach its footprint a
// share T passes (binomial, 4 σ) carrying its power times t, still direct light (not scattered),
// and the rest are reflected (scattered) or stop at the pane. The
// pane's own radiosity is what it reflects: (1 − T) t E.
TEST(Materials, AThinPaneLetsItsShareThroughTintedByItsBaseColour) {
    CardScene c = cardOverFloor(AlphaMode::Opaque, 1.0f, 1, allOpaque);
    const float T = 0.6f;
    const Vec3f tint(0.9f, 0.5f, 0.3f);
    Material& pane = c.scene.materials.back();
    pane.transmission = T;
    pane.albedo = tint;
    pane.baseColour = TextureSlot();  // the tint from the factor alone
    const SecondPassRig rig(c.scene);
    ASSERT_TRUE(rig.bvh.passesShares());
    DirectLight direct(4, 7);
    direct.computeAll(c.scene, rig.bvh, rig.starts);
    const size_t under = forEachFloorVertexUnderTheCard(c, [&](uint32_t v) {
        const Vec3f e = direct.irradiance()[v];
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(e[k], 2.0 * double(T) * double(tint[k]), 1e-6) << "channel " << k << " at vertex " << v;
    });
    EXPECT_GT(under, 500u);
    // Photons.
    TraceSettings settings;
    settings.photons = 40000;
    const PhotonTracer tracer(c.scene, rig.bvh, settings);
    const RayCache cache = tracer.traceAll();
    const MeshInstance& card = c.scene.instances[1];
    auto onCard = [&](uint32_t t) { return t >= card.firstTriangle && t < card.firstTriangle + card.triangleCount; };
    size_t arrived = 0, passed = 0;
    std::vector<Segment> path;
    for (uint64_t p = 0; p < settings.photons; ++p) {
        path.clear();
        cache.appendPath(p, path);
        if (path.empty() || !path[0].hasImpact() || !onCard(path[0].triangle)) continue;
        ++arrived;
        if (path.size() < 2) continue;  // stopped
        if (dot(path[1].direction, path[0].direction) < 0.999f) {
            ASSERT_EQ(path[1].scattered, 1) << "reflected light is scattered";
            continue;
        }
        // Light that only passed the pane is still direct light: what --direct exact computes
        // apart, so that the estimators' "after the first bounce" must not count it again.
        ASSERT_EQ(path[1].scattered, 0) << "photon " << p;
        ++passed;
        for (int k = 0; k < 3; ++k) ASSERT_NEAR(path[1].power[k], path[0].power[k] * tint[k], 1e-6f * path[0].power[k]);
    }
    const double share = double(passed) / double(arrived), sigma = std::sqrt(T * (1 - T) / double(arrived));
    std::printf("pane: %zu photons arrived, %.4f passed (T = %.1f, sigma %.4f)\n", arrived, share, T, sigma);
    ASSERT_GT(arrived, 1000u);
    EXPECT_NEAR(share, T, 4 * sigma);
    // Its vertices' reflectance.
    for (uint32_t v = card.firstVertex; v < card.firstVertex + card.vertexCount; ++v)
        for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(vertexAlbedo(c.scene, v)[k], tint[k] * (1 - T));
}

// What the loader reads of a material (docs/inputs.md): its base colour and emissive textures
// with their sampler, alpha mode and cutoff, doubleSided, KHR_materials_transmission, and each
// vertex's TEXCOORD_0 and COLOR_0; a vertex's reflectance is factor × texel × colour × (1 − T).
TEST(Materials, TheLoaderReadsTexturesVertexColoursAlphaAndTransmission) {
    const fs::path dir = testScratchDir("materials_loader");
    {
        const uint8_t pixels[8] = {255, 0, 0, 255, 0, 0, 255, 64};
        OIIO::ImageSpec spec(2, 1, 4, OIIO::TypeDesc::UINT8);
        spec.attribute("oiio:UnassociatedAlpha", 1);
        auto out = OIIO::ImageOutput::create((dir / "red_blue.png").string());
        ASSERT_TRUE(out && out->open((dir / "red_blue.png").string(), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels));
        out->close();
    }
    testscenes::GltfWriter w;
    const int positions = w.accessor({0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 1}, "VEC3");
    const int normals = w.accessor({0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0}, "VEC3");
    const int uvs = w.accessor({0.25f, 0.5f, 0.75f, 0.5f, 0.75f, 0.5f, 0.25f, 0.5f}, "VEC2");
    const int colours = w.accessor({1, 1, 1, 0.5f, 0.5f, 0.5f, 1, 0, 1, 1, 1, 1}, "VEC3");
    const int indices = w.indices({0, 2, 1, 0, 3, 2});
    w.doc["meshes"] = nlohmann::json::array({{{"primitives", {{{"attributes", {{"POSITION", positions}, {"NORMAL", normals},
                                                                               {"TEXCOORD_0", uvs}, {"COLOR_0", colours}}},
                                                               {"indices", indices}, {"material", 0}}}}}});
    w.doc["images"] = nlohmann::json::array({{{"uri", "red_blue.png"}}});
    w.doc["samplers"] = nlohmann::json::array({{{"magFilter", 9728}, {"minFilter", 9728}}});
    w.doc["textures"] = nlohmann::json::array({{{"source", 0}, {"sampler", 0}}});
    w.doc["materials"] = nlohmann::json::array(
        {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"baseColorFactor", {1, 1, 1, 1}}}},
          {"emissiveFactor", {0.5, 0.5, 0.5}},
          {"emissiveTexture", {{"index", 0}}},
          {"alphaMode", "MASK"},
          {"alphaCutoff", 0.3},
          {"doubleSided", true},
          {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 0.4}}}}}}});
    w.doc["extensionsUsed"] = {"KHR_materials_transmission"};
    w.node({{"name", "Quad"}, {"mesh", 0}});
    w.doc["scenes"] = nlohmann::json::array({{{"nodes", {0}}}});
    const fs::path path = dir / "quad.gltf";
    w.write(path.string());
    Warnings warnings;
    const Scene scene = loadGltfScene(path.string(), warnings);
    for (const std::string& m : warnings.messages) EXPECT_EQ(m.find("transmission"), std::string::npos) << m;
    ASSERT_EQ(scene.vertexCount(), 4u);
    const Material& m = scene.materials[scene.triangleMaterial[0]];
    EXPECT_TRUE(m.baseColour.used());
    EXPECT_TRUE(m.emissive.used());
    EXPECT_EQ(m.alphaMode, AlphaMode::Mask);
    EXPECT_FLOAT_EQ(m.alphaCutoff, 0.3f);
    EXPECT_TRUE(m.doubleSided);
    EXPECT_FLOAT_EQ(m.transmission, 0.4f);
    ASSERT_EQ(scene.vertexColours.size(), 4u);
    ASSERT_GE(scene.vertexTexCoords.size(), 1u);
    // Vertex 1: UV (0.75, 0.5), the blue texel (NEAREST), colour 0.5 grey, 60 % reflected.
    EXPECT_FLOAT_EQ(scene.vertexTexCoords[0][1].s, 0.75f);
    EXPECT_FLOAT_EQ(scene.vertexColours[1][0], 0.5f);
    const Vec3f rho = vertexAlbedo(scene, 1);
    EXPECT_FLOAT_EQ(rho.x, 0.0f);
    EXPECT_NEAR(rho.z, 1.0 * 0.5 * 0.6, 1e-6);
    // Vertex 2: the same texel, magenta: red 0, blue 0.6.
    EXPECT_NEAR(vertexAlbedo(scene, 2).z, 0.6, 1e-6);
    // Its emission: the factor times the texel (sRGB white in blue: 1), not times its colour.
    EXPECT_NEAR(vertexEmission(scene, 1).z, 0.5, 1e-6);
    EXPECT_EQ(vertexEmission(scene, 1).x, 0.0f);
    // The blue texel's alpha, 64/255 = 0.25 < 0.3: cut out there; the red one stays.
    const SurfaceLookup lookup(scene);
    EXPECT_TRUE(lookup.letsLightThrough(0));
    bool cut = false, kept = false;
    for (float b1 = 0.05f; b1 < 0.95f; b1 += 0.1f)
        for (float b2 = 0.05f; b1 + b2 < 0.95f; b2 += 0.1f) {
            const bool stops = lookup.stops(0, b1, b2, 0.5f);
            (stops ? kept : cut) = true;
        }
    EXPECT_TRUE(cut);
    EXPECT_TRUE(kept);
}

namespace {
// qsgi's frame against a reference of scripts/material_reference.py at its referenced vertices:
// the relative RMS and bias of the radiosity over their RGB components. `back`: qsgi's back
// columns against a reference of the back sides (material_reference.py --back).
struct ReferenceScore {
    size_t vertices = 0;
    double rms = 0, bias = 0;
};
ReferenceScore scoreAgainst(const VertexRadiosityPly& qsgi, const VertexRadiosityPly& reference, bool back) {
    ReferenceScore score;
    const std::vector<Vec3f>& ours = back ? qsgi.backRadiosity : qsgi.radiosity;
    EXPECT_EQ(ours.size(), reference.radiosity.size()) << (back ? "the back columns" : "the vertices");
    if (ours.size() != reference.radiosity.size()) return score;
    double squared = 0, difference = 0, total = 0;
    for (size_t v = 0; v < ours.size(); ++v) {
        if (!reference.referenced.empty() && !reference.referenced[v]) continue;
        EXPECT_LT(length(qsgi.positions[v] - reference.positions[v]), 1e-5f) << "vertex " << v << " is not the reference's";
        for (int c = 0; c < 3; ++c) {
            const double d = double(ours[v][c]) - double(reference.radiosity[v][c]);
            squared += d * d;
            difference += d;
            total += double(reference.radiosity[v][c]);
        }
        ++score.vertices;
    }
    const double n = 3.0 * double(score.vertices), mean = total / n;
    score.rms = std::sqrt(squared / n) / mean;
    score.bias = difference / n / mean;
    return score;
}

// The seed of the reference tests' second measurement (QSGI_REFERENCE_SEED), 1 by default.
std::string referenceSeed() {
    const char* seedText = std::getenv("QSGI_REFERENCE_SEED");
    return seedText ? seedText : "1";
}
}  // namespace

// Every feature together against an independent path tracer: the materials room
// (tests/data/materials_room, written by scripts/make_material_scenes.py materials_room — a floor
// textured in stripes through KHR_texture_transform, a COLOR_0 wall, an alpha-MASK checker card
// under a ceiling panel, a BLEND card, a box whose emissive texture is black but for a screen, and
// a thin pane (KHR_materials_transmission 0.9) over a window to the sky) rendered by the qsgi
// command with its defaults and --sky 1,1,1, against Mitsuba 3 built from the glTF itself
// (scripts/material_reference.py, 4096 paths a vertex; vertices in the card's holes are left out).
// The bounds follow tests/reference_accuracy_test.cpp's rule: the error at seed 1 plus three times
// its change between seeds 1 and 2 (both printed when QSGI_REFERENCE_SEED=2 is set). The scene
// and its reference are frozen together: regenerate both if either changes.
TEST(Materials, TheMaterialsRoomAgreesWithAnIndependentPathTracer) {
    const std::string seed = referenceSeed();
    const fs::path out = fs::path(testScratchDir("materials_room")) / ("seed" + seed);
    const CommandResult run = runQsgi("render " + (sourceDir() / "tests/data/materials_room/materials_room.gltf").string() +
                                      " --sky 1,1,1 --quiet --no-exr --seed " + seed + " --out " + out.string());
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const VertexRadiosityPly qsgi = readVertexRadiosityPly((out / "frame_0000.ply").string());
    const VertexRadiosityPly reference = readVertexRadiosityPly((sourceDir() / "tests/reference/materials_room_f0000.ply").string());
    const ReferenceScore score = scoreAgainst(qsgi, reference, false);
    std::printf("materials room (seed %s): %zu vertices, relative RMS %.4f, bias %+.4f\n", seed.c_str(), score.vertices, score.rms,
                score.bias);
    EXPECT_LT(score.rms, kMaterialsRoomRms);
    EXPECT_LT(std::abs(score.bias), kMaterialsRoomBias);
}

// Each feature alone against the same path tracer: the scenes of scripts/make_material_scenes.py
// (tests/data/material_features: a floor textured red and blue by halves, COLOR_0 walls of both
// accessor kinds, a doubleSided alpha-MASK checker card and its back side, a BLEND card, a thin
// pane to the sky, an emissive texture black but for a screen), each rendered with the defaults
// against its reference (tests/reference/material_*_f0000.ply, 4096 paths a vertex; the card's back
// sides from material_reference.py --back). Bounds by the rule above, measured at seeds 1 and 2:
// each feature's RMS at seed 1 plus three times its change, its bias's size likewise (numbers in
// the table; the references' own noise is 1–5 %, the window's most: a small opening to the sky).
TEST(Materials, EachFeatureAgreesWithAnIndependentPathTracer) {
    struct Feature {
        const char* scene;
        const char* options;
        bool back;  // the reference is of the back sides (the doubleSided card's)
        const char* reference;
        double rms, bias;  // bounds
    };
    const Feature features[] = {
        {"textured_floor", "", false, "material_textured_floor_f0000.ply", kFeatureBounds[0][0], kFeatureBounds[0][1]},
        {"vertex_colour", "", false, "material_vertex_colour_f0000.ply", kFeatureBounds[1][0], kFeatureBounds[1][1]},
        {"alpha_mask", "", false, "material_alpha_mask_f0000.ply", kFeatureBounds[2][0], kFeatureBounds[2][1]},
        {"alpha_mask", "", true, "material_alpha_mask_back_f0000.ply", kFeatureBounds[3][0], kFeatureBounds[3][1]},
        {"alpha_blend", "", false, "material_alpha_blend_f0000.ply", kFeatureBounds[4][0], kFeatureBounds[4][1]},
        {"glass_window", " --sky 1,1,1", false, "material_glass_window_f0000.ply", kFeatureBounds[5][0], kFeatureBounds[5][1]},
        {"emissive_texture", "", false, "material_emissive_texture_f0000.ply", kFeatureBounds[6][0], kFeatureBounds[6][1]},
    };
    const std::string seed = referenceSeed();
    const fs::path scratch = testScratchDir("material_features");
    std::set<std::string> rendered;  // a scene read twice (front and back) is rendered once
    for (const Feature& f : features) {
        SCOPED_TRACE(std::string(f.scene) + (f.back ? " (back sides)" : ""));
        const fs::path out = scratch / (std::string(f.scene) + "-seed" + seed);
        if (rendered.insert(f.scene).second) {
            const CommandResult run = runQsgi("render " + (sourceDir() / "tests/data/material_features" / (std::string(f.scene) + ".gltf")).string() +
                                              f.options + " --quiet --no-exr --seed " + seed + " --out " + out.string());
            ASSERT_EQ(run.exitCode, 0) << run.output;
        }
        const VertexRadiosityPly qsgi = readVertexRadiosityPly((out / "frame_0000.ply").string());
        const VertexRadiosityPly reference = readVertexRadiosityPly((sourceDir() / "tests/reference" / f.reference).string());
        const ReferenceScore score = scoreAgainst(qsgi, reference, f.back);
        std::printf("%s%s (seed %s): %zu vertices, relative RMS %.4f, bias %+.4f\n", f.scene, f.back ? " back sides" : "",
                    seed.c_str(), score.vertices, score.rms, score.bias);
        EXPECT_LT(score.rms, f.rms);
        EXPECT_LT(std::abs(score.bias), f.bias);
    }
}

// The camera composites a BLEND surface over what lies behind it: looking straight down at the
// BLEND card (alpha 0.3) over the floor, a pixel shows the card's B (which holds its alpha share
// already) plus 1 − alpha of the floor's, each divided by π; beside the card, the floor's alone.
// (The card's texture is one grey texel, so its triangles vary and take the texel path: B = its
// share × ρ × E.)
TEST(Materials, TheCameraCompositesABlendSurfaceByItsAlpha) {
    const float alpha = 0.3f;
    const CardScene c = cardOverFloor(AlphaMode::Blend, alpha, 1, allOpaque);
    const EmbreeDevice device;
    const SceneBvh bvh(device, c.scene);
    VertexRadiosity solution;
    solution.irradiance.assign(c.scene.vertexCount(), Vec3f(2.0f));
    computeRadiosity(c.scene, solution);
    Camera camera;
    camera.projection = Projection::Orthographic;
    camera.position = Vec3f(0, 3, 0);
    camera.forward = Vec3f(0, -1, 0);
    camera.up = Vec3f(0, 0, -1);
    camera.ymag = 1.0f;
    ImageSettings settings;
    settings.width = settings.height = 20;
    const RgbImage image = renderRadiosityImage(c.scene, bvh, solution, camera, settings);
    const double floorB = 2.0 * 0.5, cardB = 2.0 * 0.5 * srgbLinear128() * alpha;
    auto pixel = [&](int x, int y) { return double(image.pixels[3 * size_t(y * settings.width + x)]); };
    EXPECT_NEAR(pixel(10, 10), (cardB + (1 - alpha) * floorB) / M_PI, 1e-5) << "over the card";
    EXPECT_NEAR(pixel(0, 0), floorB / M_PI, 1e-5) << "beside it";
}
