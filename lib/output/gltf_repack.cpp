#include "output/gltf_repack.h"

#include <cstring>
#include <filesystem>

namespace qsgi {

using nlohmann::json;
namespace fs = std::filesystem;

void packBuffers(const GltfDocument& document, json& doc, BinaryBuilder& bin, Warnings& warnings, const std::string& file,
                 const std::string& assetFolder) {
    const tinygltf::Model& model = document.model;
    std::vector<size_t> start(model.buffers.size(), 0);
    for (size_t b = 0; b < model.buffers.size(); ++b) {
        bin.align(16);  // keeps every accessor's alignment within its buffer
        start[b] = bin.bytes().size();
        if (!document.absentBuffers.count(int(b))) {
            bin.bytes().append(reinterpret_cast<const char*>(model.buffers[b].data.data()), model.buffers[b].data.size());
        } else {
            // No data (no uri): nothing reads it, but its views must stay inside the one buffer.
            const size_t length = doc["buffers"][b].value("byteLength", size_t(0));
            if (length > kMaxGlbBytes) throw InputError(file, "buffers[" + std::to_string(b) + "].byteLength", "is beyond what a GLB holds");
            bin.bytes().append(length, '\0');
            warnings.add(file + ": buffers[" + std::to_string(b) + "] has no data; the asset holds zeros in its place");
        }
    }
    if (doc.contains("bufferViews"))
        for (json& view : doc["bufferViews"]) {
            const size_t b = view.value("buffer", size_t(0));
            view["buffer"] = 0;
            view["byteOffset"] = view.value("byteOffset", size_t(0)) + (b < start.size() ? start[b] : 0);
        }
    if (doc.contains("images"))
        for (size_t i = 0; i < doc["images"].size() && i < model.images.size(); ++i) {
            json& image = doc["images"][i];
            if (!image.contains("uri")) continue;
            const tinygltf::Image& decoded = model.images[i];
            const std::string uri = image["uri"].is_string() ? image["uri"].get<std::string>() : "";
            // The format the bytes are (not the name's extension, which may lie).
            const std::vector<unsigned char>& b = decoded.image;
            auto startsWith = [&](const char* magic, size_t at = 0) {
                const size_t n = std::strlen(magic);
                return b.size() >= at + n && std::memcmp(b.data() + at, magic, n) == 0;
            };
            const std::string mime = startsWith("\x89PNG") ? "image/png" : startsWith("\xFF\xD8\xFF") ? "image/jpeg"
                                   : startsWith("RIFF") && startsWith("WEBP", 8) ? "image/webp"
                                   : startsWith("\xABKTX 20\xBB") ? "image/ktx2" : "";
            if (mime.empty()) {
                // Left where it is: the uri made to reach the file from the asset's folder.
                const fs::path target = fs::path(document.baseDir) / uri;
                if (!uri.empty() && uri.rfind("data:", 0) != 0 && !assetFolder.empty())
                    image["uri"] = fs::relative(fs::absolute(target), fs::absolute(assetFolder)).generic_string();
                warnings.add(file + ": images[" + std::to_string(i) + "] ('" + uri.substr(0, 200) +
                             "') is no PNG, JPEG, WebP or KTX2 file qsgi could read, so it is not embedded; asset.glb refers to it");
                continue;
            }
            image.erase("uri");
            image["bufferView"] = bin.addView(decoded.image.data(), decoded.image.size());
            image["mimeType"] = mime;
        }
}

}  // namespace qsgi
