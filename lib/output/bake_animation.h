// The animation that plays the bake in asset.glb (lib/output/baked_asset.h). Frame k shows the
// lighting's target k − 1 at weight 1, by a STEP weights channel on every node whose mesh gained
// the targets; it goes into the animation that played (merged with that animation's own weights
// channel for the node) or, for a transform file or all animations at once, a new animation
// "qsgi" that also holds the transform file's motion as the moved nodes' translation, rotation
// and scale. Every other weights channel on those nodes is extended with zeros.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "output/bake_inputs.h"
#include "output/glb_builder.h"
#include "scene/scene.h"
#include "util/error.h"
#include "util/vecmath.h"

namespace qsgi {

// The lighting weights channels (and a transform file's motion) in the animation that played, or
// in a new one; every other animation's weights channels on those nodes extended with zeros.
// `ownTargets`: per output mesh that gained targets, the targets it had before them; `nodeMesh`:
// the nodes showing such a mesh, and which.
void addLightingAnimation(nlohmann::json& doc, BinaryBuilder& bin, const Scene& scene, const std::vector<double>& frameSeconds,
                          const std::map<int, size_t>& ownTargets,
                          const std::map<int, int>& nodeMesh, const std::vector<NodeMotion>& motion,
                          const BakedAssetSettings& settings, Warnings& warnings, const std::string& file);

// A transform file's first pose (`firstPose`, every node's local transform) given to the nodes
// where it differs from the file's: the pose the bake is of.
void giveFirstPose(nlohmann::json& doc, const std::vector<Transform>& firstPose);

}  // namespace qsgi
