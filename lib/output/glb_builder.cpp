#include "output/glb_builder.h"

#include "output/baked_asset_parts.h"
#include "util/error.h"

namespace qsgi {

using nlohmann::json;

std::string BinaryBuilder::glb() {
    // One buffer, the GLB's binary chunk.
    json buffer = doc_.contains("buffers") && !doc_["buffers"].empty() ? doc_["buffers"][0] : json::object();
    buffer.erase("uri");
    align(4);
    buffer["byteLength"] = bin_.size();
    doc_["buffers"] = json::array({std::move(buffer)});

    std::string text = doc_.dump();
    while (text.size() % 4) text += ' ';
    const uint64_t total = 12 + 8 + uint64_t(text.size()) + 8 + bin_.size();
    if (total > kMaxGlbBytes)
        throw InputError(kOption, "", "the baked asset would exceed the 4 GiB a GLB holds (" + std::to_string(total) + " bytes)");
    std::string glb;
    glb.reserve(size_t(total));
    auto u32 = [&](uint64_t v) {
        const uint32_t w = uint32_t(v);
        glb.append(reinterpret_cast<const char*>(&w), 4);
    };
    glb += "glTF";
    u32(2);
    u32(total);
    u32(text.size());
    u32(0x4E4F534A);  // JSON
    glb += text;
    u32(bin_.size());
    u32(0x004E4942);  // BIN
    glb += bin_;
    return glb;
}

}  // namespace qsgi
