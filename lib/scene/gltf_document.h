// Reading a .gltf or .glb file into tinygltf's model, with the document-level rules of the glTF 2.0
// specification that tinygltf does not enforce, and the valid constructs it refuses:
//   - asset.version must be 2.x and asset.minVersion at most 2.0;
//   - buffers and images are local files or data URIs: a remote URI (http:, https:, …) is refused;
//     a uri's file is read only if it is a regular file of sane size (never a directory, a pipe or
//     a device) that fits in memory beside the files read before it: an unreadable buffer is
//     refused, an unreadable image recorded in unreadableImages. Each is opened once and read
//     straight into tinygltf's own array (a buffer of N bytes is held as N bytes, not copied);
//   - a buffer without a uri (other than a GLB's BIN chunk) is valid as long as nothing reads it;
//     tinygltf refuses the whole file, so such buffers are handed to it as a 1-byte placeholder and
//     listed in absentBuffers, and any read through them is refused by the accessor reader.
// Everything beyond the document level (accessors, hierarchy, materials) is checked where the
// model is turned into a Scene (gltf_loader.cpp).
#pragma once

#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <map>
#include <set>
#include <string>

#include "scene/gltf_references.h"
#include "util/error.h"

namespace qsgi {

struct GltfDocument {
    tinygltf::Model model;
    // The JSON as the file holds it, before any repair made for tinygltf's sake: what --gltf-out
    // writes back (lib/output/baked_asset.h), every property kept.
    nlohmann::json json;
    std::string baseDir;  // where its uris are relative to
    std::set<int> absentBuffers;  // buffers that have no data (no uri, not the BIN chunk)
    // Broken references, empty arrays and cameras with two projections, wherever they are: the
    // loader refuses those in objects the render reads and warns about the others.
    std::vector<GltfFinding> findings;
    // Images whose uri's file was not read, and why ("is a directory, not a file"): the loader
    // warns about the ones a material uses and leaves their factor alone.
    std::map<int, std::string> unreadableImages;
};

// Throws InputError naming the file and the place in it; tinygltf's own warnings go to warnings.
GltfDocument readGltfDocument(const std::string& path, Warnings& warnings);
// The same for a file already in memory: `path` names it in messages, external URIs are read
// relative to `baseDir` (the fuzzers use this).
GltfDocument parseGltfDocument(const std::string& path, std::string bytes, const std::string& baseDir,
                               Warnings& warnings);

}  // namespace qsgi
