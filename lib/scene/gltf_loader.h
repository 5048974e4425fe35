// glTF 2.0 (.gltf with external or embedded buffers, .glb) to a render-ready Scene, through
// tinygltf. Flattens the default scene to world space (docs/design.md §2).
#pragma once

#include <string>

#include "scene/gltf_document.h"
#include "scene/scene.h"
#include "util/error.h"

namespace qsgi {

struct GltfReadOptions {
    // Refuse errors in objects the render does not use (nodes outside the default scene, their
    // meshes, skins, cameras, materials, accessors), which are otherwise warnings: for pipelines
    // that gate exporters (--strict).
    bool strict = false;
};

// Throws InputError naming the file and the place in it when the file cannot be used: any
// error in what the render reads (the default scene's nodes, their meshes, accessors, materials,
// skins and morph targets, the animations, the cameras used); errors elsewhere are warnings
// (refusals under options.strict). Recoverable oddities (ignored extensions, missing images, …)
// go to warnings.
Scene loadGltfScene(const std::string& path, Warnings& warnings, const GltfReadOptions& options = {});
// The same for a file already read (readGltfDocument): what a caller that keeps the document
// (the asset, --gltf-out) builds the scene from, so that both come from one read of the file.
Scene loadGltfScene(const GltfDocument& document, const std::string& path, Warnings& warnings, const GltfReadOptions& options = {});
// The same for a file in memory (see parseGltfDocument).
Scene loadGltfSceneFromMemory(const std::string& path, std::string bytes, const std::string& baseDir,
                              Warnings& warnings, const GltfReadOptions& options = {});

}  // namespace qsgi
