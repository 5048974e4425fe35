// The environment light (issue 35; lib/scene/environment_light.h): the map's orientation as the
// header documents it, its sampling density, reading EXR and Radiance HDR, exact direct light
// from it (π L on an open plane under a uniform sky, a rotated sun moving as the rotation says),
// photons carrying exactly π R² ∫ L dω (a convex body absorbs L ∫ A_proj dω), and the command
// line: a lightless scene lit by one flag, and refused naming the three ways to light it.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "estimate/direct_light.h"
#include "estimate/impact_count.h"
#include "output/ply_reader.h"
#include "scene/environment_light.h"
#include "test_support.h"
#include "trace/photon_tracer.h"
#include "util/error.h"

using namespace qsgi;
namespace fs = std::filesystem;

namespace {

// v = θ / π (θ from +Y) and u = φ / 2π + ½ (φ from +X toward +Z) of a direction, as the header
// defines the map.
struct MapCoordinates {
    double u, v;
};
MapCoordinates mapCoordinates(const Vec3f& w) {
    const double theta = std::acos(std::clamp(double(w.y), -1.0, 1.0));
    const double phi = std::atan2(double(w.z), double(w.x));
    return {phi / (2 * M_PI) + 0.5, theta / M_PI};
}

// A W × H map, black but for pixel (column, row).
std::vector<Vec3f> onePixelMap(uint32_t width, uint32_t height, uint32_t column, uint32_t row, Vec3f value) {
    std::vector<Vec3f> pixels(size_t(width) * height, Vec3f(0.0f));
    pixels[size_t(row) * width + column] = value;
    return pixels;
}

// n × n stratified pairs: a grid's cell centres.
template <class F>
void forGrid(int n, F&& f) {
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) f((float(i) + 0.5f) / float(n), (float(j) + 0.5f) / float(n));
}

std::shared_ptr<const EnvironmentLight> shared(EnvironmentLight light) {
    return std::make_shared<const EnvironmentLight>(std::move(light));
}

}  // namespace

TEST(EnvironmentLight, AUniformSkyIsTheOneByOneMap) {
    const Vec3f L(1.0f, 0.5f, 0.25f);
    const EnvironmentLight sky = EnvironmentLight::uniform(L);
    EXPECT_TRUE(sky.isUniform());
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sky.integral()[c], 4 * M_PI * L[c], 1e-12 * 4 * M_PI);
    // Uniform over the sphere: density 1/4π everywhere, and a 64 × 64 grid of pairs gives a mean
    // direction of 0 (each stratum of cos θ and φ is hit equally; the centres' offsets cancel).
    Vec3d mean(0.0);
    int upper = 0;
    forGrid(64, [&](float u0, float u1) {
        const EnvironmentLight::DirectionSample s = sky.sample(u0, u1);
        EXPECT_NEAR(length(Vec3d(s.towardSky)), 1.0, 1e-6);
        EXPECT_NEAR(s.pdf, 1 / (4 * M_PI), 1e-12);
        EXPECT_EQ(s.radiance, L);
        mean += Vec3d(s.towardSky);
        upper += s.towardSky.y > 0;
    });
    EXPECT_LT(length(mean) / 4096, 1e-3);
    EXPECT_EQ(upper, 2048);
    EXPECT_NEAR(sky.pdf(normalize(Vec3f(0.3f, -0.2f, 0.9f))), 1 / (4 * M_PI), 1e-12);
}

// The header's convention, Blender's and three.js's: the top row is +Y, the image's middle +X, a
// quarter to its left −Z and to its right +Z; `rotation` turns the map counter-clockwise about +Y
// seen from above.
TEST(EnvironmentLight, TheMapIsOrientedAsDocumented) {
    // 4 × 2 pixels: column 1 is u in [0.25, 0.5), φ in [−90°, 0°] (from −Z to +X); row 0 the upper
    // hemisphere. So pixel (1, 0) holds the sky between −Z and +X, above the horizon.
    const Vec3f sun(3.0f, 2.0f, 1.0f);
    const EnvironmentLight map = EnvironmentLight::fromPixels(onePixelMap(4, 2, 1, 0, sun), 4, 2, 0);
    EXPECT_EQ(map.radiance(normalize(Vec3f(0.3f, 0.5f, -0.8f))), sun);
    EXPECT_EQ(map.radiance(normalize(Vec3f(-0.3f, 0.5f, -0.8f))), Vec3f(0.0f));  // past −Z toward −X: column 0
    EXPECT_EQ(map.radiance(normalize(Vec3f(0.3f, -0.5f, -0.8f))), Vec3f(0.0f));  // below the horizon: row 1
    EXPECT_EQ(map.radiance(normalize(Vec3f(0.8f, 0.5f, 0.3f))), Vec3f(0.0f));   // past +X toward +Z: column 2
    // The image's middle is +X, its left and right edges meet at −X.
    const EnvironmentLight middle = EnvironmentLight::fromPixels(onePixelMap(4, 2, 2, 0, sun), 4, 2, 0);
    EXPECT_EQ(middle.radiance(normalize(Vec3f(0.8f, 0.5f, 0.3f))), sun);
    const EnvironmentLight edge = EnvironmentLight::fromPixels(onePixelMap(4, 2, 0, 0, sun), 4, 2, 0);
    EXPECT_EQ(edge.radiance(normalize(Vec3f(-0.8f, 0.5f, -0.3f))), sun);
    forGrid(32, [&](float u0, float u1) {
        const Vec3f w = map.sample(u0, u1).towardSky;
        EXPECT_GE(w.x, -1e-6f);
        EXPECT_GE(w.y, -1e-6f);
        EXPECT_LE(w.z, 1e-6f);
    });
    // Turned 90°: −Z goes to −X and +X to −Z, so the sun lies between −X and −Z.
    const EnvironmentLight turned = EnvironmentLight::fromPixels(onePixelMap(4, 2, 1, 0, sun), 4, 2, 90);
    EXPECT_EQ(turned.radiance(normalize(Vec3f(-0.8f, 0.5f, -0.3f))), sun);
    EXPECT_EQ(turned.radiance(normalize(Vec3f(0.3f, 0.5f, -0.8f))), Vec3f(0.0f));
    forGrid(32, [&](float u0, float u1) {
        const Vec3f a = map.sample(u0, u1).towardSky, b = turned.sample(u0, u1).towardSky;
        // The same sample, turned: (x, z) → (x cos α + z sin α, −x sin α + z cos α), α = 90°.
        EXPECT_NEAR(b.x, a.z, 1e-6f);
        EXPECT_NEAR(b.y, a.y, 1e-6f);
        EXPECT_NEAR(b.z, -a.x, 1e-6f);
    });
}

// Directions are drawn in proportion to luminance × solid angle: over a stratified grid of pairs,
// each pixel receives its probability's share of the samples, to the grid's resolution; the
// density sample() reports is the one pdf() gives; and for a grey map L / pdf is the integral
// exactly, for every sample.
TEST(EnvironmentLight, SamplesFollowLuminanceTimesSolidAngle) {
    const uint32_t W = 16, H = 8;
    std::vector<Vec3f> pixels(W * H);
    for (uint32_t i = 0; i < H; ++i)
        for (uint32_t j = 0; j < W; ++j) pixels[i * W + j] = Vec3f(float(1 + (i * 7 + j * 3) % 5));  // grey, 1..5
    pixels[3 * W + 5] = Vec3f(0.0f);  // a black pixel is never drawn
    const EnvironmentLight map = EnvironmentLight::fromPixels(pixels, W, H, 30);
    std::vector<double> probability(W * H);
    for (uint32_t i = 0; i < H; ++i)
        for (uint32_t j = 0; j < W; ++j) {
            const double solidAngle = 2 * M_PI / W * (std::cos(M_PI * i / H) - std::cos(M_PI * (i + 1) / H));
            probability[i * W + j] = double(pixels[i * W + j].x) * solidAngle / map.integral().x;
        }
    const int n = 512;
    std::vector<int> count(W * H, 0);
    int agreeing = 0;
    forGrid(n, [&](float u0, float u1) {
        const EnvironmentLight::DirectionSample s = map.sample(u0, u1);
        // Turn back by 30° to read the pixel in the map's own frame.
        const double a = -30 * M_PI / 180;
        const Vec3f m(float(s.towardSky.x * std::cos(a) + s.towardSky.z * std::sin(a)), s.towardSky.y,
                      float(-s.towardSky.x * std::sin(a) + s.towardSky.z * std::cos(a)));
        const MapCoordinates c = mapCoordinates(m);
        const uint32_t column = std::min(W - 1, uint32_t(c.u * W)), row = std::min(H - 1, uint32_t(c.v * H));
        ++count[row * W + column];
        agreeing += std::abs(map.pdf(s.towardSky) - s.pdf) <= 1e-9 * s.pdf;
        EXPECT_NEAR(double(s.radiance.x) / s.pdf, map.integral().x, 1e-9 * map.integral().x);
    });
    // A pixel's samples are those of a band of u0 (its row) times a band of u1 (within the row):
    // on an n × n grid each band is found to within one grid step, so a count is off by at most
    // about 2n + 1 of the expected n² p... and far less on average. Points on a boundary may read
    // the neighbouring pixel back (rounding); there are at most a few per pixel edge.
    const double total = double(n) * n;
    for (uint32_t p = 0; p < W * H; ++p)
        EXPECT_NEAR(count[p], probability[p] * total, 2.0 * n + 8) << "pixel " << p % W << ", " << p / W;
    EXPECT_EQ(count[3 * W + 5], 0);
    EXPECT_GE(agreeing, int(0.99 * total));
}

TEST(EnvironmentLight, ReadsExrAndRadianceHdrAndRefusesNegativePixels) {
    const fs::path dir = testScratchDir("environment_maps");
    const uint32_t W = 8, H = 4;
    std::vector<float> rgb(W * H * 3);
    for (size_t k = 0; k < rgb.size(); ++k) rgb[k] = 0.25f * float(1 + k % 7);
    auto write = [&](const fs::path& path, const std::vector<float>& values) {
        auto out = OIIO::ImageOutput::create(path.string());
        ASSERT_TRUE(out) << OIIO::geterror();
        OIIO::ImageSpec spec(int(W), int(H), 3, OIIO::TypeDesc::FLOAT);
        ASSERT_TRUE(out->open(path.string(), spec)) << out->geterror();
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, values.data())) << out->geterror();
        out->close();
    };
    write(dir / "sky.exr", rgb);
    write(dir / "sky.hdr", rgb);
    for (const char* name : {"sky.exr", "sky.hdr"}) {
        SCOPED_TRACE(name);
        const EnvironmentLight map = EnvironmentLight::fromImage((dir / name).string(), 2.0f, 0);
        ASSERT_EQ(map.width(), W);
        ASSERT_EQ(map.height(), H);
        // EXR holds the floats; RGBE keeps 8 bits of mantissa under a shared exponent (within 2^-7
        // of the largest channel).
        const double tolerance = std::string(name) == "sky.exr" ? 0.0 : 2.0 * 1.75 * 0x1p-7;
        for (size_t p = 0; p < size_t(W) * H; ++p)
            for (int c = 0; c < 3; ++c) ASSERT_NEAR(map.pixels()[p][c], 2.0f * rgb[p * 3 + size_t(c)], tolerance) << "pixel " << p;
    }
    std::vector<float> negative = rgb;
    negative[(2 * W + 5) * 3 + 1] = -1;
    write(dir / "negative.exr", negative);
    try {
        EnvironmentLight::fromImage((dir / "negative.exr").string(), 1, 0);
        FAIL() << "a negative radiance was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("negative.exr"), std::string::npos) << e.what();
        EXPECT_EQ(e.place(), "pixel (5, 2)");
    }
    EXPECT_THROW(EnvironmentLight::fromImage((dir / "absent.exr").string(), 1, 0), InputError);
}

// An open plane under a uniform sky sees the whole upper hemisphere: E = π L at every vertex,
// and the sky's cosine-distributed rays give exactly that (each π L / S), whatever S.
TEST(EnvironmentLight, APlaneUnderASkyReceivesPiTimesItsRadiance) {
    Scene scene = testscenes::plane(1.0f, 12, Vec3f(0.5f));
    const Vec3f L(0.8f, 1.0f, 1.3f);
    scene.environment = shared(EnvironmentLight::uniform(L));
    const SecondPassRig rig(scene);
    for (const uint32_t samples : {1u, 16u}) {
        DirectLight direct(samples, 3);
        direct.computeAll(scene, rig.bvh, rig.starts);
        EXPECT_EQ(direct.raysCast(), uint64_t(samples) * scene.vertexCount());
        for (uint32_t v = 0; v < scene.vertexCount(); ++v)
            for (int c = 0; c < 3; ++c)
                ASSERT_NEAR(direct.irradiance()[v][c], M_PI * L[c], 4 * 0x1p-24 * M_PI * L[c]) << "vertex " << v << ", S " << samples;
    }
}

// A sun (one pixel of an 8 × 4 map, column 2 and row 1: θ in [45°, 90°], φ in [−90°, −45°], from
// −Z a quarter of the way toward +X, above the horizon) behind a wall that faces +Z gives it nothing; turned 180° it shines on the wall's front:
// E = L ∫ ω_z dω over the pixel = L (π/8 + 1/4) sin 45° = 0.4545 L (the integral of −sin²θ sin φ).
// The estimate mixes cosine and map directions (balance heuristic), unbiased; each map direction
// contributes at most L Ω_pixel ≈ 0.555 L, so one vertex's 64-sample mean has a standard error of
// at most 0.555 L / 2 / 8 = 0.035 L for independent samples, and the mean of the wall's n vertices
// at most 0.035 L / √n: 4 standard errors is the tolerance.
TEST(EnvironmentLight, ATurnedMapMovesTheSunAsTheRotationSays) {
    const Vec3f sunRadiance(10.0f);
    const double expected = 10.0 * (M_PI / 8 + 0.25) * std::sqrt(0.5);
    const double vertexError = 0.035 * 10.0;  // the standard error bound of one vertex, above
    for (const float rotation : {0.0f, 180.0f}) {
        SCOPED_TRACE(rotation);
        Scene scene = testscenes::partition(16, Vec3f(0.5f));
        scene.environment = shared(EnvironmentLight::fromPixels(onePixelMap(8, 4, 2, 1, sunRadiance), 8, 4, rotation));
        const SecondPassRig rig(scene);
        DirectLight direct(64, 5);
        direct.computeAll(scene, rig.bvh, rig.starts);
        double sum = 0;
        int n = 0;
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3f& p = scene.positions[v];
            const bool wallFront = std::abs(p.z) < 1e-6f && p.y > 0.05f && scene.normals[v].z > 0.5f;
            if (!wallFront) continue;
            const double E = direct.irradiance()[v].x;
            if (rotation == 0) {
                ASSERT_EQ(E, 0.0) << "vertex " << v << ": the sun is behind the wall";
            } else {
                EXPECT_NEAR(E, expected, 4 * vertexError) << "vertex " << v;
            }
            sum += E;
            ++n;
        }
        ASSERT_GE(n, 30);  // the wall's front vertices above the floor's first row
        if (rotation != 0) {
            std::printf("turned sun: wall mean E %.4f, expected %.4f (%d vertices)\n", sum / n, expected, n); EXPECT_NEAR(sum / n, expected, 4 * vertexError / std::sqrt(double(n)));
        }
    }
}

// Photons from the environment carry π R² ∫ L dω between them. A convex body with albedo 0
// absorbs, from each direction ω, L(ω) times its projected area A_⊥(ω); under a uniform sky that
// sums to L ∫ A_⊥ dω = π L A (Cauchy: A_⊥ averages A/4), and under a map to ∫ L A_⊥ dω, which
// for a finely subdivided sphere is ∫ L dω · A/4 to its anisotropy (measured below 0.1 %).
// Each absorbed photon carries the same luminance, so the total is a binomial count: at 4·10^5
// photons about 1.3·10^5 hit (R = √3, cross-section ≈ π: a third of the disc), a relative standard
// error of 0.28 %; 1.5 % is over five of them.
TEST(EnvironmentLight, PhotonsCarryTheSkysPowerIntoAConvexBody) {
    std::vector<Vec3f> twoTone(8 * 4, Vec3f(0.5f, 0.4f, 0.3f));
    for (size_t p = 0; p < 16; ++p) twoTone[p] = Vec3f(2.0f, 2.0f, 1.5f);  // the upper hemisphere brighter
    const EnvironmentLight lights[] = {EnvironmentLight::uniform(Vec3f(1.0f, 0.5f, 0.25f)),
                                       EnvironmentLight::fromPixels(twoTone, 8, 4, 20)};
    for (const EnvironmentLight& light : lights) {
        SCOPED_TRACE(light.isUniform() ? "sky" : "map");
        Scene scene = testscenes::closedSphere(1.0f, 5, Vec3f(0.0f), /*inwardNormals=*/false);
        scene.environment = shared(light);
        const RayCache cache = traceScene(scene, 400000, 11);
        ImpactCount ic(scene);
        ic.accumulate(cache);
        const PowerQuantizer q(cache.maxPhotonPower);
        double area = 0;
        Vec3d absorbed(0.0);
        for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
            absorbed += ic.triangleSums()[t].watts(q);
            area += scene.triangleArea(t);
        }
        for (int c = 0; c < 3; ++c) {
            const double expected = light.integral()[c] * area / 4;
            EXPECT_NEAR(absorbed[c] / expected, 1.0, 0.015) << "channel " << c;
        }
    }
}

// A lightless scene renders with one flag and is refused, without it, naming the three ways to
// light it. On an open quad under a sky the bake is B = ρ π L: exact direct light gives π L, and
// every gather ray escapes (the sky's light is already in the direct term).
TEST(EnvironmentLight, ALightlessSceneBakesWithOneFlag) {
    const fs::path dir = testScratchDir("environment_cli");
    testscenes::writeQuadGltf((dir / "dark.gltf").string(), false);
    const std::string dark = (dir / "dark.gltf").string();
    const CommandResult refused = runQsgi("render " + dark + " --out " + (dir / "refused").string());
    EXPECT_EQ(refused.exitCode, 2) << refused.output;
    for (const char* way : {"\"lights\"", "--sky", "--environment"})
        EXPECT_NE(refused.output.find(way), std::string::npos) << refused.output;

    const CommandResult lit = runQsgi("render " + dark + " --sky 0.5,1,2 --photons 2000 --gather 8 --out " + (dir / "sky").string());
    ASSERT_EQ(lit.exitCode, 0) << lit.output;
    const VertexRadiosityPly ply = readVertexRadiosityPly((dir / "sky" / "frame_0000.ply").string());
    ASSERT_FALSE(ply.radiosity.empty());
    const Vec3f L(0.5f, 1.0f, 2.0f);
    for (const Vec3f& B : ply.radiosity) {
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(B[c], 0.5 * M_PI * L[c], 1e-5 * M_PI * L[c]);
    }

    // A black sky lights nothing (the scene is refused as unlit); one past the power floats carry
    // (10^30 W into the bounding sphere) is refused naming it, as a light that strong is.
    const CommandResult black = runQsgi("render " + dark + " --sky 0 --out " + (dir / "black").string());
    EXPECT_EQ(black.exitCode, 2) << black.output;
    EXPECT_NE(black.output.find("no lights"), std::string::npos) << black.output;
    const CommandResult blinding = runQsgi("render " + dark + " --sky 1e36 --out " + (dir / "blinding").string());
    EXPECT_EQ(blinding.exitCode, 2) << blinding.output;
    EXPECT_NE(blinding.output.find("the sky or environment map"), std::string::npos) << blinding.output;
    EXPECT_FALSE(fs::exists(dir / "blinding" / "frame_0000.ply"));

    const CommandResult missing = runQsgi("render " + dark + " --environment " + (dir / "absent.exr").string() + " --out " +
                                          (dir / "missing").string());
    EXPECT_EQ(missing.exitCode, 2) << missing.output;
    EXPECT_NE(missing.output.find("absent.exr"), std::string::npos) << missing.output;
    EXPECT_FALSE(fs::exists(dir / "missing" / "frame_0000.ply"));
}
