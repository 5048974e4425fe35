// A glTF document's animations (glTF 2.0 §3.11) as KeyframeAnimations, with the rules the
// specification sets on them checked: samplers' interpolation, input times (scalar floats,
// non-negative, strictly increasing), output types and counts for the animated property, one
// channel per target and property, no channel on a node given by a matrix.
#pragma once

#include <string>
#include <vector>

#include "scene/gltf_accessor.h"
#include "scene/keyframes.h"
#include "util/error.h"

namespace qsgi {

// Throws InputError naming the file and the place. Channels without a target node (left to
// extensions by the specification) are skipped with a warning.
std::vector<KeyframeAnimation> readGltfAnimations(const tinygltf::Model& model, const AccessorReader& reader,
                                                  const std::string& file, Warnings& warnings);

}  // namespace qsgi
