// Light from infinitely far away (docs/design.md §2, issue 35): a uniform sky, or an equirectangular
// HDR map decoded by OpenImageIO from the file's bytes (EXR, Radiance HDR, any format it reads from
// memory), static as every light is.
//
// The map's orientation, in glTF's Y-up frame, as Blender and three.js show an equirectangular
// world. Pixel column u ∈ [0, 1) (left to right) and row v ∈ [0, 1) (top to bottom) hold the
// radiance arriving from the direction ω (pointing toward the sky) with polar angle θ = π v from
// +Y and azimuth φ = 2π (u − ½) from +X toward +Z:
//   ω = (sin θ cos φ, cos θ, sin θ sin φ)
// so the top row is the zenith (+Y), the middle of the image +X, a quarter to its left −Z (where a
// glTF camera at rest looks) and a quarter to its right +Z; looking from inside, the image is the
// right way round. `rotation` turns the map about +Y by that many degrees, counter-clockwise seen
// from above (right-handed): with 90°, what was at −Z comes from −X.
//
// The map is piecewise constant: each pixel is its exact solid angle, a band of the sphere
// (2π/W)(cos θ_top − cos θ_bottom), so the light's integrals are sums, exact up to rounding. A
// uniform sky is the 1 × 1 map. Directions are drawn in proportion to luminance × solid angle
// (a pixel, then a point uniform in solid angle within it), the way an infinite light emits in a
// physically based renderer (pbrt-v4's ImageInfiniteLight).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

// What a config or the command line asks for: a uniform sky or a map, never both.
struct EnvironmentSettings {
    std::optional<Vec3f> sky;   // radiance (W m^-2 sr^-1), RGB
    std::string image;          // an equirectangular map's path ("" : none)
    float intensity = 1;        // the map's radiance is its pixels × intensity
    float rotationDegrees = 0;  // about +Y, counter-clockwise seen from above
    // Where the map was named (a config's path or "command line"), for messages.
    std::string source;

    bool given() const { return sky.has_value() || !image.empty(); }
};

class EnvironmentLight {
public:
    // A uniform sky of radiance L (finite, non-negative: the option checks).
    static EnvironmentLight uniform(const Vec3f& radiance);
    // An equirectangular map, its file opened once (util/input_file.h). Throws InputError naming
    // the file and the pixel when the file cannot be read or holds a negative, NaN or infinite
    // radiance.
    static EnvironmentLight fromImage(const std::string& path, float intensity, float rotationDegrees);
    // The same from pixels in memory (RGB, row-major from the top row): for tests and the loader.
    static EnvironmentLight fromPixels(std::vector<Vec3f> pixels, uint32_t width, uint32_t height, float rotationDegrees);

    uint32_t width() const { return width_; }
    uint32_t height() const { return height_; }
    bool isUniform() const { return width_ == 1 && height_ == 1; }
    // The radiance, row-major from the top, and the turn about +Y: what the run's fingerprint holds.
    const std::vector<Vec3f>& pixels() const { return pixels_; }
    float rotationDegrees() const { return rotationDegrees_; }

    // L(ω), ω a unit direction toward the sky.
    Vec3f radiance(const Vec3f& towardSky) const;
    // ∫ L dω over the sphere (RGB, W m^-2).
    Vec3d integral() const { return integral_; }
    // The largest max-component over luminance of any pixel that emits: bounds a photon's power
    // relative to its luminance (PowerQuantizer needs every photon's largest component).
    double largestChroma() const { return largestChroma_; }

    struct DirectionSample {
        Vec3f towardSky;  // unit
        Vec3f radiance;   // L(towardSky)
        double pdf = 0;   // per steradian: luminance(L) / ∫ luminance(L) dω
    };
    // A direction in proportion to luminance × solid angle, from two numbers in [0, 1): u0 picks
    // the row and, with what is left of it, θ within the row; u1 the pixel in the row and φ within
    // the pixel, so a stratified pair stays stratified. Never called on a light whose luminance integral is 0.
    DirectionSample sample(float u0, float u1) const;
    // The density sample() draws `towardSky` with (0 where the map is black).
    double pdf(const Vec3f& towardSky) const;


private:
    EnvironmentLight() = default;
    void buildTables();
    // The pixel a map-frame direction falls in.
    size_t pixelOf(const Vec3f& towardSky) const;
    Vec3f toWorld(const Vec3d& mapDirection) const;

    uint32_t width_ = 0, height_ = 0;
    float rotationDegrees_ = 0;
    double cosRotation_ = 1, sinRotation_ = 0;
    std::vector<Vec3f> pixels_;        // radiance, row-major from the top
    std::vector<double> rowCdf_;       // height_ + 1: luminance × solid angle, cumulative over rows
    std::vector<double> columnCdf_;    // height_ × (width_ + 1): within each row, cumulative
    std::vector<double> cosTheta_;     // height_ + 1: cos θ at each row boundary, from +1 to −1
    double luminanceIntegral_ = 0;     // ∫ luminance(L) dω
    Vec3d integral_{0.0};
    double largestChroma_ = 0;
};

}  // namespace qsgi
