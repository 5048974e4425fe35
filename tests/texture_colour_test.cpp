// Textures are decoded whole (texture_colour.h: PNG by libpng, JPEG by OpenImageIO), only when a
// material uses them, and never read outside their bytes. The checks compare the decoded pixels'
// mean linear colour with the one worked out here from the pixels written, with the sRGB curve of
// the glTF specification.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "scene/gltf_loader.h"
#include "scene/texture_colour.h"
#include "test_support.h"

using namespace qsgi;
namespace fs = std::filesystem;

namespace {

double srgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// Writes `pixels` (channels interleaved, 8 or 16 bits) with OIIO and returns the encoded bytes.
template <typename T>
std::string encoded(const std::string& name, int width, int height, int channels, const std::vector<T>& pixels,
                    int quality = 100) {
    const fs::path path = fs::path(testScratchDir("texture_colour")) / name;
    OIIO::ImageSpec spec(width, height, channels, sizeof(T) == 1 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
    spec.attribute("CompressionQuality", quality);
    if (channels == 4) spec.attribute("oiio:UnassociatedAlpha", 1);  // the colour as given, not over alpha
    auto out = OIIO::ImageOutput::create(path.string());
    EXPECT_TRUE(out && out->open(path.string(), spec)) << OIIO::geterror();
    EXPECT_TRUE(out->write_image(sizeof(T) == 1 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16, pixels.data()));
    out->close();
    return readFileBytes(path);
}

std::string base64(const std::string& bytes) {
    static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t group = uint32_t(uint8_t(bytes[i])) << 16;
        if (i + 1 < bytes.size()) group |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        if (i + 2 < bytes.size()) group |= uint8_t(bytes[i + 2]);
        for (size_t k = 0; k < 4; ++k) out += i + k <= bytes.size() ? digits[(group >> (18 - 6 * k)) & 63] : '=';
    }
    return out;
}

struct TextureColour {
    std::optional<Vec3f> mean;  // mean linear (sRGB-decoded) RGB of the decoded pixels
    std::string problem;
};

TextureColour meanOfImage(const TextureImage& image) {
    double sum[3] = {0, 0, 0};
    const size_t pixels = size_t(image.width) * image.height;
    for (size_t p = 0; p < pixels; ++p)
        for (size_t c = 0; c < 3; ++c) sum[c] += srgbToLinear(image.rgba[4 * p + c] / 255.0);
    return {Vec3f(float(sum[0] / double(pixels)), float(sum[1] / double(pixels)), float(sum[2] / double(pixels))), ""};
}

TextureColour meanOf(const std::string& bytes) {
    const DecodedTexture decoded = decodeTextureImage(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
    if (!decoded.image) return {std::nullopt, decoded.problem};
    return meanOfImage(*decoded.image);
}

// The mean colour of the base colour texture material m of a loaded scene reads.
Vec3f meanOfMaterialTexture(const Scene& scene, size_t m) {
    const TextureSlot& slot = scene.materials[m].baseColour;
    EXPECT_TRUE(slot.used()) << "material " << m << " reads no texture";
    if (!slot.used()) return Vec3f(0.0f);
    return *meanOfImage(*(*scene.textures)[size_t(slot.texture)].image).mean;
}

// The 2 x 2 texture of tests/data/good/texture_*.gltf (make_inputs.py, TEXTURE_PIXELS).
Vec3f meanOfTheTestTexture() {
    const int pixels[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {128, 128, 128}};
    double sum[3] = {0, 0, 0};
    for (const auto& p : pixels)
        for (int c = 0; c < 3; ++c) sum[c] += srgbToLinear(p[c] / 255.0);
    return Vec3f(float(sum[0] / 4), float(sum[1] / 4), float(sum[2] / 4));
}

}  // namespace

TEST(TextureColour, EmbeddedAndDataUriTexturesGiveTheirMeanLinearColourAndUnusedGarbageIsNeverRead) {
    const Vec3f expected = meanOfTheTestTexture();
    for (const char* name : {"texture_embedded.gltf", "texture_data_uri.gltf"}) {
        SCOPED_TRACE(name);
        Warnings warnings;
        const Scene scene = loadGltfScene((sourceDir() / "tests/data/good" / name).string(), warnings);
        ASSERT_GE(scene.materials.size(), 1u);
        const Vec3f mean = meanOfMaterialTexture(scene, 0);
        EXPECT_FLOAT_EQ(mean.x, expected.x);
        EXPECT_FLOAT_EQ(mean.y, expected.y);
        EXPECT_FLOAT_EQ(mean.z, expected.z);
        // images[1] is garbage that no material uses: not decoded, so not warned about.
        for (const auto& w : warnings.messages) EXPECT_EQ(w.find("images[1]"), std::string::npos) << w;
    }
}

TEST(TextureColour, UnreadableTexturesLeaveTheFactorAndSayWhy) {
    Warnings warnings;
    const Scene scene =
        loadGltfScene((sourceDir() / "tests/data/good/texture_unreadable.gltf").string(), warnings);
    ASSERT_GE(scene.materials.size(), 3u);
    for (int m = 0; m < 3; ++m) {
        EXPECT_EQ(scene.materials[m].albedo.x, 0.5f) << m;
        EXPECT_EQ(scene.materials[m].albedo.y, 0.25f) << m;
        EXPECT_EQ(scene.materials[m].albedo.z, 1.0f) << m;
    }
    const std::vector<std::pair<std::string, std::string>> expected = {
        {"materials[0]", "30000 x 30000 pixels"}, {"materials[1]", "truncated PNG"}, {"materials[2]", "neither PNG nor JPEG"}};
    for (const auto& [place, words] : expected) {
        bool said = false;
        for (const auto& w : warnings.messages)
            said = said || (w.find(place) != std::string::npos && w.find(words) != std::string::npos);
        EXPECT_TRUE(said) << place << " should be warned about: " << words;
    }
}

TEST(TextureColour, SixteenBitsAndAlphaAreReadAsStored) {
    // 16-bit RGBA, rounded to 8 bits a channel; the colour is not multiplied by alpha (glTF's
    // alpha is coverage, not premultiplied), and alpha is kept.
    const std::vector<uint16_t> pixels = {65535, 0, 30000, 0, 1000, 65535, 2, 65535};
    const std::string bytes = encoded("rgba16.png", 2, 1, 4, pixels);
    const DecodedTexture decoded = decodeTextureImage(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
    ASSERT_TRUE(decoded.image) << decoded.problem;
    for (size_t i = 0; i < pixels.size(); ++i)
        EXPECT_EQ(decoded.image->rgba[i], uint8_t((uint32_t(pixels[i]) * 255 + 32767) / 65535)) << "value " << i;
}

TEST(TextureColour, GreyImagesGiveGrey) {
    const std::vector<uint8_t> pixels = {0, 64, 200};
    const TextureColour colour = meanOf(encoded("grey.png", 3, 1, 1, pixels));
    ASSERT_TRUE(colour.mean) << colour.problem;
    const float grey = float((srgbToLinear(0) + srgbToLinear(64 / 255.0) + srgbToLinear(200 / 255.0)) / 3);
    EXPECT_FLOAT_EQ(colour.mean->x, grey);
    EXPECT_FLOAT_EQ(colour.mean->y, grey);
    EXPECT_FLOAT_EQ(colour.mean->z, grey);
}

TEST(TextureColour, AFlatJpegGivesItsColourWithinOneQuantisationStep) {
    // JPEG is lossy: a flat 8 x 8 block of one colour comes back within a level or two of it.
    const uint8_t rgb[3] = {200, 100, 30};
    std::vector<uint8_t> pixels;
    for (int p = 0; p < 64; ++p) pixels.insert(pixels.end(), rgb, rgb + 3);
    const std::string bytes = encoded("flat.jpg", 8, 8, 3, pixels);
    const TextureColour colour = meanOf(bytes);
    ASSERT_TRUE(colour.mean) << colour.problem;
    const float got[3] = {colour.mean->x, colour.mean->y, colour.mean->z};
    for (int c = 0; c < 3; ++c) {
        const double slope = (srgbToLinear((rgb[c] + 2) / 255.0) - srgbToLinear((rgb[c] - 2) / 255.0));
        EXPECT_NEAR(got[c], srgbToLinear(rgb[c] / 255.0), slope) << "channel " << c;
    }
    // Cut short, it is reported, not read past its end.
    const TextureColour cut = meanOf(bytes.substr(0, bytes.size() / 3));
    EXPECT_FALSE(cut.mean);
    EXPECT_FALSE(cut.problem.empty());
}

// Valid PNGs a decoder may get wrong (tests/data/good/texture_png_variants.gltf): an Adam7-
// interlaced one, read pass by pass, every pixel once; and a row of 1,100,000 pixels, wider than
// libpng's default limit of 10^6 (OpenImageIO refused it, printing "libpng error").
TEST(TextureColour, InterlacedAndVeryWidePngsGiveTheirMean) {
    // The file's floor uses material 0; a copy whose floor uses material 1 reads the wide one (a
    // scene keeps the textures of the materials it renders).
    const fs::path file = sourceDir() / "tests/data/good/texture_png_variants.gltf";
    nlohmann::json doc = nlohmann::json::parse(readFileBytes(file));
    doc["meshes"][0]["primitives"][0]["material"] = 1;
    const fs::path wideFile = fs::path(testScratchDir("texture_colour_wide")) / "wide.gltf";
    std::ofstream(wideFile) << doc.dump();
    Warnings warnings;
    const Scene scene = loadGltfScene(file.string(), warnings), wideScene = loadGltfScene(wideFile.string(), warnings);
    for (const auto& w : warnings.messages) EXPECT_EQ(w.find("materials["), std::string::npos) << w;
    double sum[3] = {0, 0, 0};
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 5; ++x)
            for (int c = 0; c < 3; ++c) sum[c] += srgbToLinear(((x * 37 + y * 11 + c * 50) % 256) / 255.0);
    ASSERT_GE(scene.materials.size(), 2u);
    const Vec3f interlaced = meanOfMaterialTexture(scene, 0), wide = meanOfMaterialTexture(wideScene, 1);
    EXPECT_FLOAT_EQ(interlaced.x, float(sum[0] / 15));
    EXPECT_FLOAT_EQ(interlaced.y, float(sum[1] / 15));
    EXPECT_FLOAT_EQ(interlaced.z, float(sum[2] / 15));
    EXPECT_FLOAT_EQ(wide.x, float(srgbToLinear(128 / 255.0)));
    EXPECT_FLOAT_EQ(wide.z, float(srgbToLinear(128 / 255.0)));
}

// Broken JPEGs go through OpenImageIO, which takes over libjpeg's error and message routines: a
// file cut short, one with its entropy-coded data scrambled and one whose frame header says 0
// rows are reported or read, and nothing but qsgi prints, with --quiet or without.
TEST(TextureColour, BrokenJpegsPrintNothingButQsgisWords) {
    std::vector<uint8_t> pixels;
    for (int p = 0; p < 16 * 16; ++p) pixels.insert(pixels.end(), {uint8_t(p), uint8_t(255 - p), 90});
    const std::string jpeg = encoded("broken.jpg", 16, 16, 3, pixels, 90);
    std::string scrambled = jpeg;
    const size_t scan = scrambled.find("\xFF\xDA");
    ASSERT_NE(scan, std::string::npos);
    for (size_t i = scan + 20; i + 2 < scrambled.size(); i += 7) scrambled[i] = char(scrambled[i] ^ 0x5A);
    std::string noRows = jpeg;
    const size_t frame = noRows.find("\xFF\xC0");
    ASSERT_NE(frame, std::string::npos);
    noRows[frame + 5] = 0;  // the frame header's height
    noRows[frame + 6] = 0;
    const std::vector<std::string> broken = {jpeg.substr(0, jpeg.size() / 2), scrambled, noRows};

    nlohmann::json doc = nlohmann::json::parse(readFileBytes(sourceDir() / "tests/data/good/texture_data_uri.gltf"));
    doc["images"] = doc["textures"] = doc["materials"] = nlohmann::json::array();
    for (size_t i = 0; i < broken.size(); ++i) {
        doc["images"].push_back({{"uri", "data:image/jpeg;base64," + base64(broken[i])}});
        doc["textures"].push_back({{"source", i}});
        doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", i}}}}}});
    }
    const fs::path dir = testScratchDir("texture_colour_jpeg");
    std::ofstream(dir / "scene.gltf") << doc.dump();
    const std::string render = "render " + (dir / "scene.gltf").string() + " --photons 1000 --out ";
    const CommandResult quiet = runQsgi(render + (dir / "quiet").string() + " --quiet");
    EXPECT_EQ(quiet.exitCode, 0) << quiet.output;
    EXPECT_EQ(quiet.output, "") << "--quiet prints errors only";
    const CommandResult loud = runQsgi(render + (dir / "loud").string());
    EXPECT_EQ(loud.exitCode, 0) << loud.output;
    std::istringstream lines(loud.output);
    for (std::string line; std::getline(lines, line);) EXPECT_EQ(line.rfind("qsgi: ", 0), 0u) << line;
}
