#include "scene/animation.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <unordered_map>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>

#include "scene/swept_boxes.h"
#include "util/error.h"
#include "util/input_file.h"
#include "util/json_file.h"
#include "util/nearest_name.h"

namespace qsgi {

using nlohmann::json;

Animation Animation::still(const Scene& scene) {
    Animation a;
    a.rest_ = scene.restLocals();
    return a;
}

namespace {

// A node by "#index" or by name (the first node of that name), through a map built once: a file
// naming many nodes of a large scene costs a lookup each, not a scan of every node.
int findNode(const Scene& scene, const std::unordered_map<std::string, int>& byName, const std::string& name) {
    if (!name.empty() && name[0] == '#') {
        const std::string digits = name.substr(1);
        if (!digits.empty() && digits.find_first_not_of("0123456789") == std::string::npos && digits.size() < 10) {
            const long i = std::stol(digits);
            if (i < long(scene.nodes.size())) return int(i);
        }
        return -1;
    }
    const auto it = byName.find(name);
    return it == byName.end() ? -1 : it->second;
}

std::vector<double> numbers(const json& j, size_t count, const std::string& file, const std::string& place) {
    if (!j.is_array() || j.size() != count)
        throw InputError(file, place, "must be an array of " + std::to_string(count) + " numbers");
    std::vector<double> out;
    for (const json& v : j) {
        if (!v.is_number()) throw InputError(file, place, "must hold only numbers");
        const double d = v.get<double>();
        if (!std::isfinite(d)) throw InputError(file, place, "holds a non-finite number");
        out.push_back(d);
    }
    return out;
}

Transform parseNodeTransform(const json& j, const std::string& file, const std::string& place) {
    if (!j.is_object()) throw InputError(file, place, "must be an object with matrix or translation/rotation/scale");
    refuseUnknownKeys(j, {"matrix", "translation", "rotation", "scale"}, file, place);
    Transform t;
    if (j.contains("matrix")) {
        if (j.size() != 1) throw InputError(file, place, "matrix cannot be combined with translation/rotation/scale");
        const std::vector<double> m = numbers(j["matrix"], 16, file, place + ".matrix");
        t = Transform::fromColumnMajor(m.data());
        // As on a glTF node: a matrix that is no translation, rotation and scale is refused.
        const std::string problem = trsDecompositionProblem(t);
        if (!problem.empty()) throw InputError(file, place + ".matrix", problem);
    } else {
        Vec3d tr(0.0), sc(1.0);
        std::array<double, 4> rot{0, 0, 0, 1};
        if (j.contains("translation")) {
            auto v = numbers(j["translation"], 3, file, place + ".translation");
            tr = {v[0], v[1], v[2]};
        }
        if (j.contains("rotation")) {
            auto v = numbers(j["rotation"], 4, file, place + ".rotation");
            if (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3] < 1e-12)
                throw InputError(file, place + ".rotation", "is a zero quaternion");
            rot = {v[0], v[1], v[2], v[3]};
        }
        if (j.contains("scale")) {
            auto v = numbers(j["scale"], 3, file, place + ".scale");
            sc = {v[0], v[1], v[2]};
        }
        t = Transform::fromTRS(tr, rot, sc);
    }
    // A singular transform (a zero scale) hides the node for the frame (docs/design.md §3).
    if (!t.isFinite()) throw InputError(file, place, "transform is not finite");
    return t;
}

}  // namespace

Animation Animation::fromTransformFile(const std::string& path, const Scene& scene) {
    return fromTransformFileBytes(path, readInputFile(path, kMaxJsonFileBytes, "a transform file"), scene);
}

Animation Animation::fromTransformFileBytes(const std::string& path, const std::string& bytes, const Scene& scene) {
    try {
        return parseTransformFile(path, parseJsonFile(path, bytes), scene);
    } catch (const json::exception& e) {
        throw InputError(path, "", std::string("a field has the wrong JSON type (") + e.what() + ")");
    }
}

Animation Animation::parseTransformFile(const std::string& path, const nlohmann::json& doc, const Scene& scene) {
    if (!doc.is_object()) throw InputError(path, "", "must be a JSON object");
    refuseUnknownKeys(doc, {"format", "version", "fps", "frames"}, path, "");
    if (doc.value("format", "") != "qsgi-animation")
        throw InputError(path, "format", "must be \"qsgi-animation\"");
    if (!doc.contains("version") || !doc["version"].is_number_integer() || doc["version"].get<int>() != 1)
        throw InputError(path, "version", "must be 1");
    Animation a = still(scene);
    if (doc.contains("fps")) {
        if (!doc["fps"].is_number() || !(doc["fps"].get<double>() > 0) || !std::isfinite(doc["fps"].get<double>()))
            throw InputError(path, "fps", "must be a positive number");
        a.fps_ = doc["fps"].get<double>();
    }
    if (!doc.contains("frames") || !doc["frames"].is_array() || doc["frames"].empty())
        throw InputError(path, "frames", "must be a non-empty array");

    std::unordered_map<std::string, int> byName;
    for (size_t i = scene.nodes.size(); i-- > 0;) byName[scene.nodes[i].name] = int(i);  // the first of a name wins
    int previousFrame = -1;
    std::vector<Key> keys;
    for (size_t i = 0; i < doc["frames"].size(); ++i) {
        const json& f = doc["frames"][i];
        std::string place = "frames[" + std::to_string(i) + "]";
        if (!f.is_object() || !f.contains("frame") || !f["frame"].is_number_integer())
            throw InputError(path, place, "must be an object with an integer \"frame\"");
        refuseUnknownKeys(f, {"frame", "nodes"}, path, place);
        const int64_t frame = f["frame"].get<int64_t>();
        if (frame < 0 || frame > 10000000) throw InputError(path, place + ".frame", "must lie in [0, 10^7]");
        if (frame <= previousFrame)
            throw InputError(path, place, "frame " + std::to_string(frame) + (frame == previousFrame ? " is duplicated" : " is out of order") +
                                              " (frames must increase)");
        previousFrame = int(frame);
        place = "frame " + std::to_string(frame);
        Key key{int(frame), {}};
        if (f.contains("nodes")) {
            if (!f["nodes"].is_object()) throw InputError(path, place + ".nodes", "must be an object keyed by node name");
            for (auto it = f["nodes"].begin(); it != f["nodes"].end(); ++it) {
                const int node = findNode(scene, byName, it.key());
                if (node < 0) {
                    std::vector<std::string> names;
                    for (const SceneNode& n : scene.nodes) names.push_back(n.name);
                    throw InputError(path, place + ", node '" + it.key() + "'",
                                     "no such node in " + scene.sourcePath + didYouMean(it.key(), names));
                }
                key.nodes.emplace_back(node, parseNodeTransform(it.value(), path, place + ", node '" + it.key() + "'"));
            }
        }
        // A node named twice in one frame (by its name and by #index) would have two transforms.
        std::vector<int> named;
        for (const auto& [node, transform] : key.nodes) named.push_back(node);
        std::sort(named.begin(), named.end());
        const auto twice = std::adjacent_find(named.begin(), named.end());
        if (twice != named.end())
            throw InputError(path, place, "names node " + std::to_string(*twice) + " ('" + scene.nodes[size_t(*twice)].name +
                                              "') twice (by its name and by #index?)");
        keys.push_back(std::move(key));
    }
    a.lastFrame_ = previousFrame;
    a.name_ = "transform file " + path;
    a.lastFrameReason_ = a.name_ + " lists frames up to " + std::to_string(previousFrame);
    a.indexKeys(keys);
    return a;
}

double Animation::lastFrameAt(double endSeconds, double fps) {
    // Frame f shows time f / fps; the last frame is the first at or past the last key. Key times
    // are float32, so a key meant for frame 41 may lie a few ulps past it: that is frame 41.
    return std::max(0.0, std::ceil(endSeconds * fps * (1 - 1e-6)));
}

Animation Animation::fromGltf(const Scene& scene, int index, double fps, const std::string& source) {
    if (scene.animations.empty()) throw InputError(source, "", "the scene has no glTF animation");
    auto listing = [&] {
        std::string names;
        for (size_t i = 0; i < scene.animations.size(); ++i)
            names += (i ? ", " : "") + std::to_string(i) + " '" + scene.animations[i].name + "'";
        return " (the file has " + names + ")";
    };
    if (index < -1 || index >= int(scene.animations.size()))
        throw InputError(source, "", "there is no glTF animation " + std::to_string(index) + listing());
    if (!(fps > 0) || !std::isfinite(fps)) throw InputError(source, "fps", "must be a positive number");
    std::vector<const KeyframeAnimation*> played;
    for (size_t i = 0; i < scene.animations.size(); ++i)
        if (index < 0 || int(i) == index) played.push_back(&scene.animations[i]);
    // Played together, two animations must not drive one property of one node.
    std::map<std::pair<int, AnimatedProperty>, const KeyframeAnimation*> driver;
    std::set<int> animated;
    double end = 0;
    for (const KeyframeAnimation* anim : played) {
        end = std::max(end, anim->endTime);
        for (const AnimationChannel& c : anim->channels) {
            auto [it, fresh] = driver.emplace(std::make_pair(c.node, c.property), anim);
            if (!fresh)
                throw InputError(source, "", "animations '" + it->second->name + "' and '" + anim->name +
                                                 "' both drive the " + animatedPropertyName(c.property) + " of node '" +
                                                 scene.nodes[c.node].name + "'; choose one with --animation gltf:N" +
                                                 listing());
            if (c.property != AnimatedProperty::Weights) animated.insert(c.node);
        }
    }
    const double lastFrame = lastFrameAt(end, fps);
    if (!(lastFrame <= 10000000))
        throw InputError(source, "fps", "the animation's " + std::to_string(end) + " s at " + std::to_string(fps) +
                                            " frames per second exceed 10^7 frames");
    Animation a = still(scene);
    a.fps_ = fps;
    a.lastFrame_ = int(std::max(0.0, lastFrame));
    // Its name and why it ends where it does, for messages about frames beyond it.
    auto named = [&](size_t i) {
        const std::string& name = scene.animations[i].name;  // "animation i" where the file gives none
        return "glTF animation " + std::to_string(i) + (name == "animation " + std::to_string(i) ? "" : " '" + name + "'");
    };
    const bool together = played.size() > 1;
    a.name_ = together ? "the scene's " + std::to_string(played.size()) + " glTF animations, played together"
                       : named(index < 0 ? size_t(0) : size_t(index));
    a.noChannels_ = std::all_of(played.begin(), played.end(), [](const KeyframeAnimation* p) { return p->channels.empty(); });
    char keys[128];
    std::snprintf(keys, sizeof keys, " keys up to %g s: frames 0 to %d at %g fps", end, a.lastFrame_, fps);
    a.lastFrameReason_ = a.name_ + (together ? " have" : " has") +
                         (a.noChannels_ ? std::string(" no channels to play, so ") + (together ? "they move" : "it moves") +
                                              " nothing and " + (together ? "have" : "has") + " frame 0 alone"
                                        : std::string(keys));
    // Frames are sampled when asked for (poseAt), so a long animation costs no memory per frame.
    auto sampled = std::make_shared<SampledAnimations>();
    for (const KeyframeAnimation* anim : played) sampled->played.push_back(*anim);
    sampled->restTrs.resize(scene.nodes.size());
    for (size_t n = 0; n < scene.nodes.size(); ++n)
        if (scene.nodes[n].trs) sampled->restTrs[n] = *scene.nodes[n].trs;
    sampled->animated.assign(animated.begin(), animated.end());
    a.sampled_ = std::move(sampled);
    // One scan of every frame: each transform must be usable (the first that is not is named),
    // and a node moves, or morphs, if it differs from frame 0 at some frame.
    const Pose first = a.poseAt(0);
    std::set<int> moved, morphed;
    for (int frame = 0; frame <= a.lastFrame_; ++frame) {
        const Pose p = a.poseAt(frame);
        for (int node : a.sampled_->animated) {
            const Transform& t = p.locals[size_t(node)];
            // A singular one (a zero scale) hides the node for the frame (docs/design.md §3).
            if (!t.isFinite())
                throw InputError(source, "frame " + std::to_string(frame) + " (" + std::to_string(frame / fps) +
                                             " s), node '" + scene.nodes[node].name + "'",
                                 "the animated transform is not finite");
            if (!(t == first.locals[size_t(node)])) moved.insert(node);
        }
        for (size_t node = 0; node < p.morphWeights.size(); ++node)
            if (p.morphWeights[node] != first.morphWeights[node]) morphed.insert(int(node));
    }
    a.moved_.assign(moved.begin(), moved.end());
    a.morphed_.assign(morphed.begin(), morphed.end());
    return a;
}

void Animation::indexKeys(const std::vector<Key>& keys) {
    std::vector<int> trackOf(rest_.size(), -1);
    for (const Key& k : keys)
        for (const auto& [node, t] : k.nodes) {
            if (trackOf[size_t(node)] < 0) {
                trackOf[size_t(node)] = int(tracks_.size());
                tracks_.push_back({node, {}, {}});
            }
            NodeTrack& track = tracks_[size_t(trackOf[size_t(node)])];
            track.frames.push_back(k.frame);
            track.transforms.push_back(t);
        }
    // Between keys nothing changes, so a node moves iff some key gives it another transform than
    // it has at frame 0.
    const std::vector<Transform> first = localsAt(0);
    std::set<int> moved;
    for (const NodeTrack& track : tracks_)
        for (const Transform& t : track.transforms)
            if (!(t == first[size_t(track.node)])) moved.insert(track.node);
    moved_.assign(moved.begin(), moved.end());
}

Pose Animation::poseAt(int frame) const {
    Pose pose(localsAt(frame), std::vector<std::vector<double>>(rest_.size()));
    if (sampled_) {  // only glTF animations drive morph weights
        const double time = std::clamp(frame, 0, lastFrame_) / fps_;
        for (const KeyframeAnimation& anim : sampled_->played)
            for (const AnimationChannel& c : anim.channels)
                if (c.property == AnimatedProperty::Weights) {
                    std::vector<double>& w = pose.morphWeights[size_t(c.node)];
                    w.resize(size_t(c.track.components));
                    c.track.sample(time, false, w.data());
                }
    }
    return pose;
}

std::vector<Transform> Animation::localsAt(int frame) const {
    std::vector<Transform> locals = rest_;
    if (sampled_) {
        std::vector<NodeTrs> trs = sampled_->restTrs;
        const double time = std::clamp(frame, 0, lastFrame_) / fps_;
        for (const KeyframeAnimation& anim : sampled_->played) anim.apply(time, trs);
        for (int node : sampled_->animated) locals[size_t(node)] = trs[size_t(node)].matrix();
        return locals;
    }
    for (const NodeTrack& track : tracks_) {
        const auto after = std::upper_bound(track.frames.begin(), track.frames.end(), frame);
        if (after != track.frames.begin()) locals[size_t(track.node)] = track.transforms[size_t(after - track.frames.begin() - 1)];
    }
    return locals;
}

void checkLightsAreStatic(const Scene& scene, const Animation& animation, const std::string& animationFile) {
    const std::vector<uint8_t> dynamicInstance = scene.dynamicInstances(animation.movedNodes(), animation.morphedNodes());
    std::vector<uint8_t> dynamicNode(scene.nodes.size(), 0);
    std::vector<int> stack(animation.movedNodes());
    while (!stack.empty()) {
        const int n = stack.back();
        stack.pop_back();
        if (dynamicNode[n]) continue;
        dynamicNode[n] = 1;
        for (int c : scene.nodes[n].children) stack.push_back(c);
    }
    for (const PunctualLight& l : scene.lights)
        if (l.node >= 0 && dynamicNode[l.node])
            throw InputError(animationFile, "node '" + scene.nodes[l.node].name + "'",
                             "moves light '" + l.name + "', but lights must be static");
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const MeshInstance& inst = scene.instances[i];
        if (dynamicInstance[i] && inst.vertexCount > 0 && scene.materials[scene.vertexMaterial[inst.firstVertex]].isEmissive())
            throw InputError(animationFile, "node '" + scene.nodes[inst.node].name + "'",
                             std::string(inst.deforms() && !dynamicNode[inst.node] ? "deforms" : "moves") +
                                 " an emissive mesh, but lights must be static");
    }
}

void sweepAnimationBounds(Scene& scene, const Animation& animation) {
    sweepAnimationBounds(scene, animation.lastFrame(), [&](int frame) { return animation.poseAt(frame); });
}

namespace {
// Boxes kept per moving instance: each segment of a frame's tracking build is tested against
// them all (Envelope::meets), so a few; eight follow a mover across a room closely enough.
constexpr size_t kSweptBoxesPerInstance = 8;
}  // namespace

void sweepAnimationBounds(Scene& scene, int lastFrame, const std::function<Pose(int)>& poseAt) {
    Bounds3f swept = scene.bounds();
    // Per instance, its bounds at every pose that moved it, in time order.
    std::vector<std::vector<Bounds3f>> poses(scene.instances.size());
    std::vector<uint32_t> moved;
    for (int frame = 0; frame <= lastFrame; ++frame) {
        moved.clear();
        if (!scene.applyPose(poseAt(frame), &moved)) continue;
        swept.extend(scene.bounds());
        for (uint32_t i : moved) {
            poses[i].push_back(scene.instanceBounds(i));
            // A pose that overflows float (NaN escapes min/max) makes the swept bounds endless,
            // which checkSceneExtent refuses.
            const MeshInstance& inst = scene.instances[i];
            for (uint32_t v = 0; v < inst.vertexCount; ++v)
                if (!isFinite(scene.positions[inst.firstVertex + v])) {
                    swept.extend(Vec3f(std::numeric_limits<float>::infinity()));
                    break;
                }
        }
    }
    moved.clear();
    scene.applyPose(scene.restPose(), &moved);
    // An instance that moved away from its rest pose was somewhere in between at rest too.
    for (uint32_t i : moved) poses[i].push_back(scene.instanceBounds(i));
    scene.animationBounds = swept;
    scene.sweptBoxes.clear();
    for (const std::vector<Bounds3f>& p : poses)
        for (const Bounds3f& b : sweptBoxes(p, kSweptBoxesPerInstance)) scene.sweptBoxes.push_back(b);
}

}  // namespace qsgi
