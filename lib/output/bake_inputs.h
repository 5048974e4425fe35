// What asset.glb's encoding is given (lib/output/baked_asset.h): each frame's bake, a transform
// file's motion and the settings. A header of their own so that the encoding's parts
// (bake_groups, bake_targets, bake_animation) take them without including their coordinator.
#pragma once

#include <string>
#include <vector>

#include "scene/keyframes.h"
#include "util/vecmath.h"

namespace qsgi {

// One frame's bake, per scene vertex.
struct BakedFrame {
    double seconds = 0;             // the animation time the frame shows
    std::vector<Vec3f> radiance;    // B/π
    std::vector<Vec3f> irradiance;  // E
    // The back sides' (lib/scene/back_sides.h), beside the front vertex: empty when no surface is
    // doubleSided, 0 at a vertex of a single-sided one.
    std::vector<Vec3f> backRadiance, backIrradiance;
};

// A transform file's motion of one node: its local transform at every frame.
struct NodeMotion {
    int node = -1;
    std::vector<NodeTrs> frames;
};

struct BakedAssetSettings {
    int colourSet = -1;      // COLOR_n to add, or -1
    double exposure = 1;     // COLOR_n = min(1, exposure · B/π)
    int playedAnimation = -1;  // the glTF animation the frames show, or -1 (none, all, or a transform file)
    bool playedAll = false;    // the file's animations played together (each node's lighting joins the one driving its weights)
    // With a transform file: every node's local transform at the first frame, which the asset's
    // nodes are given where the file's differ (the pose the bake is of); empty otherwise.
    std::vector<Transform> firstPose;
    std::string assetFolder;   // where the asset goes: an image left outside is referred to from there
};

}  // namespace qsgi
