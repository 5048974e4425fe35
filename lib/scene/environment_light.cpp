#include "scene/environment_light.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include "util/error.h"
#include "util/input_file.h"
#include "util/memory.h"

namespace qsgi {

namespace {

// 16384 × 8192, the largest maps in common use; 32 bytes a pixel while loading (the file's floats,
// the radiance and the sampling table).
constexpr uint64_t kMaxEnvironmentPixels = uint64_t(1) << 27;
// The sampling tables' bytes a pixel (buildTables: a double of the conditional CDF).
constexpr uint64_t kTableBytesPerPixel = sizeof(double);

// The first index k in [0, n) with cdf[k + 1] > target, for cdf[0..n] increasing: the cell
// `target` falls in, skipping empty cells.
size_t cellOf(const double* cdf, size_t n, double target) {
    const size_t k = size_t(std::upper_bound(cdf + 1, cdf + n + 1, target) - (cdf + 1));
    return std::min(k, n - 1);
}

}  // namespace

EnvironmentLight EnvironmentLight::uniform(const Vec3f& radiance) { return fromPixels({radiance}, 1, 1, 0); }

EnvironmentLight EnvironmentLight::fromPixels(std::vector<Vec3f> pixels, uint32_t width, uint32_t height,
                                              float rotationDegrees) {
    EnvironmentLight e;
    e.width_ = width;
    e.height_ = height;
    e.pixels_ = std::move(pixels);
    e.rotationDegrees_ = rotationDegrees;
    const double a = double(rotationDegrees) * M_PI / 180.0;
    e.cosRotation_ = std::cos(a);
    e.sinRotation_ = std::sin(a);
    e.buildTables();
    return e;
}

EnvironmentLight EnvironmentLight::fromImage(const std::string& path, float intensity, float rotationDegrees) {
    // The one opening rule first: a pipe, a device (/dev/zero) or a directory is refused by its
    // kind before anything reads it (a pipe's open would wait for a writer, a device's bytes never
    // end). OpenImageIO then decodes the bytes read from that descriptor, from memory: it never
    // opens the path itself, which could name another file by then.
    InputFile file(path, kMaxImageFileBytes, "an environment map");
    refuseBeyondMemory(file.size(), path, "", "reading the environment map's " + std::to_string(file.size()) + " bytes");
    const std::string bytes = file.readAll();
    OIIO::Filesystem::IOMemReader memory(bytes.data(), bytes.size());
    // The path still chooses the format to try first by its extension, as a file's open does.
    auto input = OIIO::ImageInput::open(path, nullptr, &memory);
    if (!input) throw InputError(path, "", "cannot be read as an image: " + oneLine(OIIO::geterror()));
    // A format whose reader cannot take bytes (SGI, FITS, Cineon, …) has opened the path instead.
    if (!input->supports("ioproxy"))
        throw InputError(path, "", std::string("is an image in the '") + input->format_name() +
                                       "' format, which OpenImageIO reads only by opening the path again, not from the "
                                       "bytes qsgi checked; convert it to OpenEXR or Radiance HDR");
    const OIIO::ImageSpec& spec = input->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1)
        throw InputError(path, "", "has no pixels");
    if (uint64_t(spec.width) * uint64_t(spec.height) > kMaxEnvironmentPixels)
        throw InputError(path, "", std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                                       " pixels is more than an environment map may have (2^27)");
    const uint32_t width = uint32_t(spec.width), height = uint32_t(spec.height);
    // Grey maps are read as one channel and spread to three; colour maps as their first three (R,
    // G, B; alpha ignored).
    const int channels = spec.nchannels >= 3 ? 3 : 1;
    // What loading holds at once, before any of it is allocated: the file's bytes, its floats,
    // OpenImageIO's own copy of them while it converts, the radiance and the sampling tables.
    const uint64_t pixelCount = uint64_t(width) * height;
    refuseBeyondMemory(saturatingAdd(bytes.size(), saturatingMultiply(pixelCount, 2 * 4 * uint64_t(channels) + sizeof(Vec3f) +
                                                                                      kTableBytesPerPixel)),
                       path, "",
                       "an environment map of " + std::to_string(width) + " x " + std::to_string(height) + " pixels");
    std::vector<float> raw(size_t(width) * height * size_t(channels));
    if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, raw.data()))
        throw InputError(path, "", "is truncated or corrupt: " + oneLine(input->geterror()));
    std::vector<Vec3f> pixels(size_t(width) * height);
    for (size_t p = 0; p < pixels.size(); ++p) {
        const float* c = &raw[p * size_t(channels)];
        const Vec3f value = channels == 3 ? Vec3f(c[0], c[1], c[2]) : Vec3f(c[0]);
        if (!isFinite(value) || value.x < 0 || value.y < 0 || value.z < 0)
            throw InputError(path, "pixel (" + std::to_string(p % width) + ", " + std::to_string(p / width) + ")",
                             "radiance must be finite and non-negative");
        pixels[p] = value * intensity;
        if (!isFinite(pixels[p]))
            throw InputError(path, "pixel (" + std::to_string(p % width) + ", " + std::to_string(p / width) + ")",
                             "radiance times the intensity is beyond single precision");
    }
    return fromPixels(std::move(pixels), width, height, rotationDegrees);
}

void EnvironmentLight::buildTables() {
    const size_t w = width_, h = height_;
    cosTheta_.resize(h + 1);
    for (size_t i = 0; i <= h; ++i) cosTheta_[i] = std::cos(M_PI * double(i) / double(h));
    cosTheta_[0] = 1;
    cosTheta_[h] = -1;
    rowCdf_.assign(h + 1, 0.0);
    columnCdf_.assign(h * (w + 1), 0.0);
    integral_ = Vec3d(0.0);
    largestChroma_ = 0;
    for (size_t i = 0; i < h; ++i) {
        const double solidAngle = 2 * M_PI / double(w) * (cosTheta_[i] - cosTheta_[i + 1]);
        double* column = &columnCdf_[i * (w + 1)];
        for (size_t j = 0; j < w; ++j) {
            const Vec3f& L = pixels_[i * w + j];
            const double lum = double(luminance(L));
            column[j + 1] = column[j] + lum * solidAngle;
            integral_ += Vec3d(L) * solidAngle;
            if (lum > 0) largestChroma_ = std::max(largestChroma_, double(maxComponent(L)) / lum);
        }
        rowCdf_[i + 1] = rowCdf_[i] + column[w];
    }
    luminanceIntegral_ = rowCdf_[h];
}

Vec3f EnvironmentLight::toWorld(const Vec3d& m) const {
    // About +Y by the rotation, right-handed.
    return Vec3f(Vec3d(m.x * cosRotation_ + m.z * sinRotation_, m.y, -m.x * sinRotation_ + m.z * cosRotation_));
}

size_t EnvironmentLight::pixelOf(const Vec3f& towardSky) const {
    const Vec3d w(towardSky);
    // The inverse rotation brings ω into the map's frame.
    const double x = w.x * cosRotation_ - w.z * sinRotation_, z = w.x * sinRotation_ + w.z * cosRotation_;
    const double y = std::clamp(w.y, -1.0, 1.0);
    const double theta = std::acos(y), phi = std::atan2(z, x);
    const size_t i = std::min(size_t(height_) - 1, size_t(theta / M_PI * double(height_)));
    const double u = phi / (2 * M_PI) + 0.5;
    const size_t j = std::min(size_t(width_) - 1, size_t(std::max(0.0, u * double(width_))));
    return i * width_ + j;
}

Vec3f EnvironmentLight::radiance(const Vec3f& towardSky) const { return pixels_[pixelOf(towardSky)]; }

double EnvironmentLight::pdf(const Vec3f& towardSky) const {
    return luminanceIntegral_ > 0 ? double(luminance(pixels_[pixelOf(towardSky)])) / luminanceIntegral_ : 0.0;
}

EnvironmentLight::DirectionSample EnvironmentLight::sample(float u0, float u1) const {
    const size_t w = width_, h = height_;
    const size_t i = cellOf(rowCdf_.data(), h, double(u0) * rowCdf_[h]);
    const double* column = &columnCdf_[i * (w + 1)];
    const size_t j = cellOf(column, w, double(u1) * column[w]);
    // Where in the pixel: what is left of each number once its cell is chosen, uniform in cos θ
    // and φ, that is, uniform in solid angle.
    auto remainder = [](double u, double lo, double hi) { return hi > lo ? std::clamp((u - lo) / (hi - lo), 0.0, 1.0) : 0.5; };
    const double r0 = remainder(double(u0) * rowCdf_[h], rowCdf_[i], rowCdf_[i + 1]);
    const double r1 = remainder(double(u1) * column[w], column[j], column[j + 1]);
    const double cosTheta = cosTheta_[i] + r0 * (cosTheta_[i + 1] - cosTheta_[i]);
    const double sinTheta = std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta));
    const double phi = 2 * M_PI * ((double(j) + r1) / double(w) - 0.5);
    DirectionSample s;
    s.towardSky = normalize(toWorld(Vec3d(sinTheta * std::cos(phi), cosTheta, sinTheta * std::sin(phi))));
    s.radiance = pixels_[i * w + j];
    s.pdf = double(luminance(s.radiance)) / luminanceIntegral_;
    return s;
}

}  // namespace qsgi
