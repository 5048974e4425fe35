// glTF 2.0 (.gltf with external or embedded buffers, .glb) to a render-ready Scene, through
// tinygltf. Flattens the default scene to world space (DESIGN §2).
#pragma once

#include <string>

#include "scene/scene.h"
#include "util/error.h"

namespace qsgi {

// Throws InputError naming the file and the place in it when the file cannot be used.
// Recoverable oddities (ignored extensions, morph targets, missing images, …) go to warnings.
Scene loadGltfScene(const std::string& path, Warnings& warnings);
// The same for a file in memory (see parseGltfDocument).
Scene loadGltfSceneFromMemory(const std::string& path, std::string bytes, const std::string& baseDir,
                              Warnings& warnings);

}  // namespace qsgi
