// The input's own data in asset.glb (lib/output/baked_asset.h): a GLB has one binary chunk, so the
// input's buffers are placed in it one after another and its images' files after them.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "output/glb_builder.h"
#include "scene/gltf_document.h"
#include "util/error.h"

namespace qsgi {

// The input's buffers, images and views moved into one buffer: every bufferView's buffer becomes
// 0 at its buffer's offset; an image's uri becomes a view of its file's bytes. An image whose
// bytes are no format a GLB embeds stays a file, its uri made to reach it from `assetFolder`.
void packBuffers(const GltfDocument& document, nlohmann::json& doc, BinaryBuilder& bin, Warnings& warnings, const std::string& file,
                 const std::string& assetFolder);

}  // namespace qsgi
