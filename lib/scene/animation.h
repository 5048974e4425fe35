// Per-frame node transforms (docs/design.md §3), from a qsgi-animation transform file (a node's entry
// replaces its local transform; nodes not listed keep their last transform) or from the scene's
// own glTF animations, sampled at a frame rate (frame f shows time f / fps).
//
// A node moves if its local transform at some frame differs from frame 0's: constant channels,
// which exporters write for every node, move nothing. Frame 0's pose is the scene's rest pose for
// the run (Scene::setRestPose), so static geometry is placed, and built into the BVH, once.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace qsgi {

class Animation {
public:
    // No animation: one frame, 0, in the rest pose.
    static Animation still(const Scene& scene);
    // Throws InputError naming the file, frame and node for anything unusable.
    static Animation fromTransformFile(const std::string& path, const Scene& scene);
    // The same for the transform file's bytes, read once by the caller (kMaxJsonFileBytes at
    // most): the run parses them here and fingerprints the same bytes, so the file is opened once
    // and what is fingerprinted is what was parsed. `path` names the file in messages.
    static Animation fromTransformFileBytes(const std::string& path, const std::string& bytes, const Scene& scene);
    // The same for a transform file already parsed as JSON (`path` names it in messages; the
    // fuzzer uses this). Wrong JSON types may also throw nlohmann::json::exception.
    static Animation parseTransformFile(const std::string& path, const nlohmann::json& doc, const Scene& scene);
    // The scene's glTF animation `index` (all of them at once if -1), sampled at `fps` from time
    // 0 through the last key. `source` names the animation in messages (e.g. "scene.gltf,
    // --animation gltf:1"). Throws InputError if there is no such animation, if animations played
    // together drive the same node property, or if a frame's transform is not finite (a singular one hides the node, docs/design.md §3).
    static Animation fromGltf(const Scene& scene, int index, double fps, const std::string& source);
    // The last frame of a glTF animation whose keys end at endSeconds, sampled at fps.
    static double lastFrameAt(double endSeconds, double fps);

    int lastFrame() const { return lastFrame_; }
    double fps() const { return fps_; }
    // What plays, as messages name it: "glTF animation 1 'Walk'", "the scene's 3 glTF animations,
    // played together", "transform file anim.json"; "" for still().
    const std::string& name() const { return name_; }
    // Why lastFrame() is what it is, as a clause naming the animation, for a message about frames
    // beyond it: "glTF animation 0 'Idle' has no channels to play, so it moves nothing and has
    // frame 0 alone", "glTF animation 1 'Walk' has keys up to 1.5 s: frames 0 to 36 at 24 fps",
    // "transform file anim.json lists frames up to 59"; "" for still().
    const std::string& lastFrameReason() const { return lastFrameReason_; }
    // Whether the animation has no channel to play (glTF animations without channels, or whose
    // every channel was skipped): it moves nothing and has frame 0 alone.
    bool hasNoChannels() const { return noChannels_; }
    // Local transform of every node at the frame (frames past the last keep the last pose).
    std::vector<Transform> localsAt(int frame) const;
    // The whole pose at the frame: local transforms and the morph weights the animation drives.
    Pose poseAt(int frame) const;
    // Nodes whose local transform differs from frame 0's in some frame.
    const std::vector<int>& movedNodes() const { return moved_; }
    // Nodes whose morph target weights differ from frame 0's in some frame.
    const std::vector<int>& morphedNodes() const { return morphed_; }

private:
    struct Key {
        int frame;
        std::vector<std::pair<int, Transform>> nodes;
    };
    // glTF animations, sampled at frame / fps when asked (shared: copies of an Animation are cheap).
    struct SampledAnimations {
        std::vector<KeyframeAnimation> played;
        std::vector<NodeTrs> restTrs;  // per node: what channels do not drive
        std::vector<int> animated;     // nodes with a translation, rotation or scale channel
    };
    // A transform file's keys of one node, frames increasing: localsAt finds the one in force by
    // binary search, so a file of many frames is read in n log n, not n^2.
    struct NodeTrack {
        int node;
        std::vector<int> frames;
        std::vector<Transform> transforms;
    };
    void indexKeys(const std::vector<Key>& keys);  // a transform file's keys into tracks_, and the moved nodes

    std::vector<Transform> rest_;
    std::vector<NodeTrack> tracks_;  // a transform file's keys, by node
    std::shared_ptr<const SampledAnimations> sampled_;  // or glTF animations
    std::vector<int> moved_, morphed_;
    int lastFrame_ = 0;
    double fps_ = 24;
    std::string name_, lastFrameReason_;
    bool noChannels_ = false;
};

// Poses the scene at every frame of the animation and sets scene.animationBounds to the union of
// their bounds, then returns the scene to its rest pose. Everything derived from the scene's size
// uses it, so no value depends on which frame is being rendered (docs/design.md §6 step 0).
void sweepAnimationBounds(Scene& scene, const Animation& animation);
// The same for any source of poses: localsAt(frame) for frames 0…lastFrame.
void sweepAnimationBounds(Scene& scene, int lastFrame, const std::function<Pose(int)>& poseAt);

// Lights are static (docs/design.md §2): throws InputError if a punctual light or an emissive mesh hangs
// under a node the animation moves, or an emissive mesh deforms.
void checkLightsAreStatic(const Scene& scene, const Animation& animation, const std::string& animationFile);

}  // namespace qsgi
