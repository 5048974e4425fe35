#include "scene/texture_colour.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

#include "util/error.h"
#include "util/memory.h"

namespace qsgi {
namespace {

// The container's signature decides the reader (the mimeType and the file name may lie).
const char* extensionOf(const unsigned char* bytes, size_t size) {
    static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    static const unsigned char jpeg[3] = {0xFF, 0xD8, 0xFF};
    if (size >= sizeof png && std::memcmp(bytes, png, sizeof png) == 0) return "png";
    if (size >= sizeof jpeg && std::memcmp(bytes, jpeg, sizeof jpeg) == 0) return "jpg";
    return nullptr;
}

std::string tooManyPixels(uint64_t width, uint64_t height) {
    return "is " + std::to_string(width) + " x " + std::to_string(height) +
           " pixels, more than qsgi decodes (16384 x 16384); skipped";
}

// Where a decoder puts the pixels: once the size (before any row, so that a sink may refuse
// nothing and allocate once), then every row, top to bottom (an interlaced PNG pass by pass,
// each row with the x and y of its pixels).
class RowSink {
public:
    virtual ~RowSink() = default;
    // "" to go on, or why the image is not taken (decoding stops there).
    virtual std::string begin(uint32_t width, uint32_t height, bool sixteen) = 0;
    // `pixels` pixels of `channels` interleaved values (grey is one channel, grey and alpha two);
    // 16-bit values in the given byte order. Pixel i lies at (x0 + i·dx, y) of the image.
    virtual void addRow(const unsigned char* row, size_t pixels, int channels, bool bigEndian, uint32_t y, uint32_t x0,
                        uint32_t dx) = 0;
};

// The pixels as stored, 8 bits a channel, RGBA (TextureImage): 16-bit values rounded to 8.
class ImageRows : public RowSink {
public:
    explicit ImageRows(uint64_t budget) : budget_(budget) {}
    std::string begin(uint32_t width, uint32_t height, bool sixteen) override {
        const uint64_t bytes = 4 * uint64_t(width) * height;
        if (bytes > budget_)
            return "is " + std::to_string(width) + " x " + std::to_string(height) + " pixels, which would need " +
                   formatBytes(bytes) + " decoded, more than the " + formatBytes(budget_) + " of memory left for textures; skipped";
        image_ = std::make_shared<TextureImage>();
        image_->width = width;
        image_->height = height;
        image_->rgba.assign(size_t(width) * height * 4, 255);
        sixteen_ = sixteen;
        return "";
    }
    void addRow(const unsigned char* row, size_t pixels, int channels, bool bigEndian, uint32_t y, uint32_t x0,
                uint32_t dx) override {
        auto value = [&](size_t at) -> uint8_t {
            if (!sixteen_) return row[at];
            const unsigned char* v = row + 2 * at;
            const uint32_t wide = bigEndian ? (uint32_t(v[0]) << 8 | v[1]) : (uint32_t(v[1]) << 8 | v[0]);
            return uint8_t((wide * 255 + 32767) / 65535);
        };
        for (size_t i = 0; i < pixels; ++i) {
            uint8_t* out = image_->rgba.data() + 4 * (size_t(y) * image_->width + x0 + i * dx);
            const size_t at = i * size_t(channels);
            for (int c = 0; c < 3; ++c) out[c] = value(at + size_t(channels >= 3 ? c : 0));
            if (channels == 2 || channels == 4) out[3] = value(at + size_t(channels - 1));
        }
    }
    std::shared_ptr<const TextureImage> take() { return std::move(image_); }

private:
    uint64_t budget_;
    std::shared_ptr<TextureImage> image_;
    bool sixteen_ = false;
};

// ---- PNG ----
// PNGs are decoded with libpng directly, under qsgi's own error handler. OpenImageIO's PNG reader
// (2.4) installs an error handler that returns, so libpng falls back to its default one, which
// prints "libpng error: …" on stderr for every broken file (a bad header, a CRC or zlib error,
// data that ends early, a width past libpng's default limit), whatever --quiet says. Here an error
// jumps back with its message and nothing is printed; warnings are dropped. The header is checked
// first, so the common faults are reported in qsgi's words.

uint32_t bigEndian32(const unsigned char* p) {
    return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

struct PngHeader {
    uint32_t width = 0, height = 0;
    int bitDepth = 0, colourType = 0, compression = 0, filter = 0, interlace = 0;
};

// Why the PNG is not one libpng reads, in qsgi's words; "" if its structure is sound. Its chunks
// lie inside the bytes and end with IEND (a cut-off download is the commonest broken texture),
// and IHDR, the first, holds values PNG defines (PNG specification §11.2.2).
std::string pngHeaderProblem(const unsigned char* bytes, size_t size, PngHeader& h) {
    size_t at = 8;
    bool ended = false;
    while (!ended && at + 12 <= size) {
        const uint64_t length = bigEndian32(bytes + at);
        if (length > size - at - 12) break;
        ended = std::memcmp(bytes + at + 4, "IEND", 4) == 0;
        at += 12 + size_t(length);
    }
    if (!ended) return "is a truncated PNG (its chunks end before IEND)";
    if (bigEndian32(bytes + 8) != 13 || std::memcmp(bytes + 12, "IHDR", 4) != 0)
        return "is a PNG without its header (IHDR, 13 bytes, must be the first chunk)";
    const unsigned char* ihdr = bytes + 16;
    h = {bigEndian32(ihdr), bigEndian32(ihdr + 4), ihdr[8], ihdr[9], ihdr[10], ihdr[11], ihdr[12]};
    const uint32_t most = 0x7FFFFFFF;
    if (h.width == 0 || h.height == 0 || h.width > most || h.height > most)
        return "is a PNG of " + std::to_string(h.width) + " x " + std::to_string(h.height) +
               " pixels (IHDR: width and height must lie in 1..2^31-1)";
    static const std::pair<int, int> depths[] = {{0, 0x1F}, {2, 0x18}, {3, 0x0F}, {4, 0x18}, {6, 0x18}};  // bits: 1 2 4 8 16
    const std::string colourDepth = "colour type " + std::to_string(h.colourType) + " with bit depth " + std::to_string(h.bitDepth);
    bool allowed = false, knownType = false;
    for (const auto& [type, mask] : depths)
        if (type == h.colourType) {
            knownType = true;
            for (int bit = 0; bit < 5; ++bit) allowed = allowed || ((mask >> bit & 1) && h.bitDepth == 1 << bit);
        }
    if (!knownType) return "is a PNG of IHDR colour type " + std::to_string(h.colourType) + ", which PNG does not define";
    if (!allowed) return "is a PNG of IHDR " + colourDepth + ", a combination PNG does not allow";
    if (h.compression != 0)
        return "is a PNG of IHDR compression method " + std::to_string(h.compression) + " (PNG defines only 0, deflate)";
    if (h.filter != 0) return "is a PNG of IHDR filter method " + std::to_string(h.filter) + " (PNG defines only 0)";
    if (h.interlace > 1)
        return "is a PNG of IHDR interlace method " + std::to_string(h.interlace) + " (PNG defines 0, none, and 1, Adam7)";
    return "";
}

// libpng's read state over bytes in memory, destroyed however decoding ends.
struct PngDecoder {
    const unsigned char* bytes;
    size_t size, at = 0;
    char error[256] = "";  // libpng's message, when it stopped
    png_structp png = nullptr;
    png_infop info = nullptr;
    PngDecoder(const unsigned char* b, size_t s) : bytes(b), size(s) {}
    PngDecoder(const PngDecoder&) = delete;
    PngDecoder& operator=(const PngDecoder&) = delete;
    ~PngDecoder() {
        if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
    }
};

void pngStop(png_structp png, png_const_charp message) {
    PngDecoder& d = *static_cast<PngDecoder*>(png_get_error_ptr(png));
    std::snprintf(d.error, sizeof d.error, "%s", message ? message : "unknown error");
    png_longjmp(png, 1);  // never returns to libpng, which would print the message
}

void pngIgnoreWarning(png_structp, png_const_charp) {}

void pngReadBytes(png_structp png, png_bytep out, size_t length) {
    PngDecoder& d = *static_cast<PngDecoder*>(png_get_io_ptr(png));
    if (length > d.size - d.at) png_error(png, "the data ends early");
    std::memcpy(out, d.bytes + d.at, length);
    d.at += length;
}

// Runs `work` (libpng calls, and no object with a destructor of its own, since an error jumps
// over its frame); false if libpng stopped with an error.
template <typename Work>
bool withPngErrors(PngDecoder& d, Work&& work) {
    if (setjmp(png_jmpbuf(d.png))) return false;
    work();
    return true;
}

// Decodes a PNG into `sink`; "" or why it could not.
std::string decodePng(const unsigned char* bytes, size_t size, RowSink& sink) {
    PngHeader header;
    const std::string problem = pngHeaderProblem(bytes, size, header);
    if (!problem.empty()) return problem;
    if (uint64_t(header.width) * header.height > kMaxTexturePixels) return tooManyPixels(header.width, header.height);
    PngDecoder d(bytes, size);
    d.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &d, pngStop, pngIgnoreWarning);
    if (d.png) d.info = png_create_info_struct(d.png);
    if (!d.png || !d.info) return "cannot be decoded: libpng could not start";
    png_set_read_fn(d.png, &d, pngReadBytes);
    // libpng refuses more than 10^6 pixels a side by default; the pixel count is qsgi's limit.
    png_set_user_limits(d.png, 0x7FFFFFFF, 0x7FFFFFFF);
    int channels = 0;
    size_t rowBytes = 0;
    if (withPngErrors(d, [&] {
            png_read_info(d.png, d.info);
            png_set_expand(d.png);  // palette to RGB, grey below 8 bits to 8, tRNS to alpha
            png_read_update_info(d.png, d.info);
            channels = png_get_channels(d.png, d.info);
            rowBytes = png_get_rowbytes(d.png, d.info);
        })) {
        const std::string refused = sink.begin(header.width, header.height, header.bitDepth == 16);
        if (!refused.empty()) return refused;
        std::vector<unsigned char> row(rowBytes);
        // A row at a time; an interlaced image pass by pass, its rows as the pass holds them
        // (each pixel lies in exactly one pass), so memory stays at one row.
        if (withPngErrors(d, [&] {
                for (int pass = 0; pass < (header.interlace ? 7 : 1); ++pass) {
                    const uint32_t cols = header.interlace ? PNG_PASS_COLS(header.width, pass) : header.width;
                    const uint32_t rows = header.interlace ? PNG_PASS_ROWS(header.height, pass) : header.height;
                    if (cols == 0) continue;  // libpng skips such passes
                    const uint32_t x0 = header.interlace ? PNG_PASS_START_COL(pass) : 0;
                    const uint32_t dx = header.interlace ? 1u << PNG_PASS_COL_SHIFT(pass) : 1;
                    const uint32_t y0 = header.interlace ? PNG_PASS_START_ROW(pass) : 0;
                    const uint32_t dy = header.interlace ? 1u << PNG_PASS_ROW_SHIFT(pass) : 1;
                    for (uint32_t r = 0; r < rows; ++r) {
                        png_read_row(d.png, row.data(), nullptr);
                        sink.addRow(row.data(), cols, channels, true, y0 + r * dy, x0, dx);
                    }
                }
            }))
            return "";
    }
    return std::string("is a corrupt PNG (libpng: ") + d.error + ")";
}

// ---- JPEG ----
// Through OpenImageIO, whose JPEG reader takes over both of libjpeg's message routines
// (error_exit and output_message), so libjpeg prints nothing.
std::string decodeJpeg(const unsigned char* bytes, size_t size, RowSink& sink) {
    OIIO::Filesystem::IOMemReader memory(bytes, size);
    // OIIO picks its plugin by the name's extension, so the name handed to it is "texture.jpg".
    auto input = OIIO::ImageInput::create("jpg");
    if (!input || !input->supports("ioproxy") || !input->set_ioproxy(&memory))
        return "cannot be decoded: this OpenImageIO cannot read jpg from memory";
    OIIO::ImageSpec config, opened;
    config.attribute("oiio:UnassociatedAlpha", 1);
    if (!input->open("texture.jpg", opened, config)) return "cannot be decoded: " + oneLine(input->geterror());
    const OIIO::ImageSpec& spec = input->spec();
    const size_t width = size_t(std::max(spec.width, 0)), height = size_t(std::max(spec.height, 0));
    const int channels = spec.nchannels;
    if (width == 0 || height == 0 || channels <= 0 || spec.depth > 1) return "has no pixels";
    if (width > kMaxTexturePixels / height) return tooManyPixels(width, height);
    const bool sixteen = spec.format.size() > 1;
    const OIIO::TypeDesc readAs = sixteen ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8;
    const std::string refused = sink.begin(uint32_t(width), uint32_t(height), sixteen);
    if (!refused.empty()) return refused;
    std::vector<unsigned char> row(width * size_t(channels) * (sixteen ? 2 : 1));
    for (int y = spec.y; y < spec.y + spec.height; ++y) {
        if (!input->read_scanline(y, spec.z, readAs, row.data()))
            return "is truncated or corrupt: " + oneLine(input->geterror());
        // native order: little-endian, as every machine qsgi builds on
        sink.addRow(row.data(), width, channels, false, uint32_t(y - spec.y), 0, 1);
    }
    return "";
}

std::string decode(const unsigned char* bytes, size_t size, RowSink& sink) {
    const char* extension = extensionOf(bytes, size);
    if (!extension) return "is neither PNG nor JPEG (the image formats glTF 2.0 allows)";
    return std::strcmp(extension, "png") == 0 ? decodePng(bytes, size, sink) : decodeJpeg(bytes, size, sink);
}

}  // namespace

DecodedTexture decodeTextureImage(const unsigned char* bytes, size_t size, uint64_t budget) {
    DecodedTexture out;
    ImageRows rows(budget);
    out.problem = decode(bytes, size, rows);
    if (out.problem.empty()) out.image = rows.take();
    return out;
}

}  // namespace qsgi
