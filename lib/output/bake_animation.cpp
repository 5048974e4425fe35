#include "output/bake_animation.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "scene/keyframes.h"

namespace qsgi {

using nlohmann::json;

namespace {

// A node's local transform as its JSON gives it (glTF 2.0 §5.25: a matrix, or T·R·S).
Transform nodeTransform(const json& node) {
    if (node.contains("matrix")) {
        const std::vector<double> m = node["matrix"].get<std::vector<double>>();
        return Transform::fromColumnMajor(m.data());
    }
    const std::vector<double> t = node.value("translation", std::vector<double>{0, 0, 0});
    const std::vector<double> r = node.value("rotation", std::vector<double>{0, 0, 0, 1});
    const std::vector<double> s = node.value("scale", std::vector<double>{1, 1, 1});
    return Transform::fromTRS(Vec3d(t[0], t[1], t[2]), {r[0], r[1], r[2], r[3]}, Vec3d(s[0], s[1], s[2]));
}

// Gives the node translation, rotation and scale (instead of a matrix, which glTF does not animate).
void setNodeTrs(json& node, const NodeTrs& trs) {
    node.erase("matrix");
    node["translation"] = {trs.translation.x, trs.translation.y, trs.translation.z};
    node["rotation"] = {trs.rotation[0], trs.rotation[1], trs.rotation[2], trs.rotation[3]};
    node["scale"] = {trs.scale.x, trs.scale.y, trs.scale.z};
}

// glTF's weights of a node at rest: its own, else its mesh's, else zeros.
std::vector<double> restWeights(const json& node, const json& mesh, size_t count) {
    std::vector<double> w(count, 0.0);
    const json* given = node.contains("weights") ? &node["weights"] : mesh.contains("weights") ? &mesh["weights"] : nullptr;
    if (given)
        for (size_t i = 0; i < count && i < given->size(); ++i) w[i] = (*given)[i].get<double>();
    return w;
}

const char* interpolationKeyword(Interpolation i) {
    return i == Interpolation::Step ? "STEP" : i == Interpolation::Linear ? "LINEAR" : "CUBICSPLINE";
}

// The track of animation `a`'s channel driving node `node`'s weights, as the scene read it.
const KeyframeTrack* weightsTrack(const Scene& scene, size_t a, int node) {
    if (a >= scene.animations.size()) return nullptr;
    for (const AnimationChannel& c : scene.animations[a].channels)
        if (c.node == node && c.property == AnimatedProperty::Weights) return &c.track;
    return nullptr;
}

}  // namespace

void addLightingAnimation(json& doc, BinaryBuilder& bin, const Scene& scene, const std::vector<double>& frameSeconds,
                          const std::map<int, size_t>& ownTargets,
                          const std::map<int, int>& nodeMesh, const std::vector<NodeMotion>& motion,
                          const BakedAssetSettings& settings, Warnings& warnings, const std::string& file) {
    if (!doc.contains("animations")) doc["animations"] = json::array();
    json& animations = doc["animations"];
    const size_t fileAnimations = animations.size();
    size_t played = size_t(settings.playedAnimation);
    if (settings.playedAnimation < 0 || !motion.empty() || played >= fileAnimations) {
        animations.push_back({{"name", "qsgi"}, {"channels", json::array()}, {"samplers", json::array()}});
        played = animations.size() - 1;
    }
    // Key times are floats in the file: the frames' as floats, strictly increasing.
    std::vector<float> frameTimes;
    for (const double t : frameSeconds) frameTimes.push_back(float(t));
    const size_t frames = frameTimes.size(), lighting = frames - 1;
    int frameTimesAccessor = -1;
    auto frameTimesIndex = [&] {
        if (frameTimesAccessor < 0) frameTimesAccessor = bin.addScalars(frameTimes, true);
        return frameTimesAccessor;
    };
    auto addSampler = [&](json& animation, int input, int output, Interpolation interpolation) {
        animation["samplers"].push_back({{"input", input}, {"output", output}, {"interpolation", interpolationKeyword(interpolation)}});
        return int(animation["samplers"].size()) - 1;
    };
    // Which frame shows at time t: the last whose time is at or before t (the first before them all).
    auto frameAtTime = [&](float t) {
        const size_t after = size_t(std::upper_bound(frameTimes.begin(), frameTimes.end(), t) - frameTimes.begin());
        return after == 0 ? size_t(0) : after - 1;
    };

    for (const NodeMotion& m : motion) {
        json& node = doc["nodes"][size_t(m.node)];
        if (node.contains("matrix")) setNodeTrs(node, m.frames.front());
        std::vector<float> translation, rotation, scale;
        for (const NodeTrs& trs : m.frames) {
            for (int c = 0; c < 3; ++c) translation.push_back(float(trs.translation[c]));
            for (int c = 0; c < 4; ++c) rotation.push_back(float(trs.rotation[size_t(c)]));
            for (int c = 0; c < 3; ++c) scale.push_back(float(trs.scale[c]));
        }
        json& animation = animations[played];
        const std::pair<const char*, std::pair<const std::vector<float>*, const char*>> paths[] = {
            {"translation", {&translation, "VEC3"}}, {"rotation", {&rotation, "VEC4"}}, {"scale", {&scale, "VEC3"}}};
        for (const auto& [path, data] : paths) {
            const int sampler = addSampler(animation, frameTimesIndex(), bin.addFloats(*data.first, data.second, frames), Interpolation::Linear);
            animation["channels"].push_back({{"sampler", sampler}, {"target", {{"node", m.node}, {"path", path}}}});
        }
    }

    // An output of animation weights: sparse where most of it is 0 (the one-hot lighting part of
    // many frames would otherwise grow with the square of the frame count).
    auto addWeights = [&](const std::vector<float>& values) {
        std::vector<uint32_t> indices;
        std::vector<float> nonzero;
        for (size_t i = 0; i < values.size(); ++i)
            if (values[i] != 0.0f) {
                indices.push_back(uint32_t(i));
                nonzero.push_back(values[i]);
            }
        if (indices.size() * 2 >= values.size()) return bin.addFloats(values, "SCALAR", values.size());
        json accessor = {{"componentType", kFloat}, {"count", values.size()}, {"type", "SCALAR"}};
        if (!indices.empty())
            accessor["sparse"] = {{"count", indices.size()},
                                  {"indices", {{"bufferView", bin.addView(indices.data(), indices.size() * 4)}, {"componentType", kUnsignedInt}}},
                                  {"values", {{"bufferView", bin.addView(nonzero.data(), nonzero.size() * 4)}}}};
        return bin.addAccessor(std::move(accessor));
    };
    auto oneHot = [&](size_t frame, std::vector<float>& values) {
        for (size_t i = 0; i < lighting; ++i) values.push_back(frame == i + 1 ? 1.0f : 0.0f);
    };
    for (const auto& [node, mesh] : nodeMesh) {
        const size_t own = ownTargets.at(mesh);
        const std::vector<double> rest = restWeights(doc["nodes"][size_t(node)], doc["meshes"][size_t(mesh)], own);
        // The animation that shows this node's lighting: the one played, or with all played at
        // once, the one already driving its weights (two channels on them would fight).
        size_t home = played;
        if (settings.playedAll)
            for (size_t a = 0; a < fileAnimations; ++a)
                if (animations[a].contains("channels"))
                    for (const json& c : animations[a]["channels"])
                        if (c.contains("target") && c["target"].value("node", -1) == node && c["target"].value("path", "") == "weights") home = a;
        bool drivenInHome = false;
        for (size_t a = 0; a < animations.size(); ++a) {
            json& animation = animations[a];
            if (!animation.contains("channels")) continue;
            for (json& channel : animation["channels"]) {
                if (!channel.contains("target") || channel["target"].value("node", -1) != node ||
                    channel["target"].value("path", "") != "weights")
                    continue;
                const json& sampler = animation["samplers"][channel["sampler"].get<size_t>()];
                const KeyframeTrack* track = weightsTrack(scene, a, node);
                KeyframeTrack zeros;  // a channel the loader did not keep (its data all zeros by default)
                if (!track) {
                    zeros.interpolation = sampler.value("interpolation", "LINEAR") == "STEP" ? Interpolation::Step
                                        : sampler.value("interpolation", "LINEAR") == "CUBICSPLINE" ? Interpolation::CubicSpline
                                                                                                   : Interpolation::Linear;
                    zeros.components = int(own);
                    const json& input = doc["accessors"][sampler["input"].get<size_t>()];
                    zeros.times.assign(input.value("count", size_t(1)), 0.0);
                    for (size_t k = 0; k < zeros.times.size(); ++k) zeros.times[k] = double(k);  // placeholders: only their count is used
                    zeros.values.assign(zeros.times.size() * own * (zeros.interpolation == Interpolation::CubicSpline ? 3 : 1), 0.0);
                    track = &zeros;
                }
                std::vector<float> keys(track->times.begin(), track->times.end());
                std::vector<float> values;
                Interpolation interpolation = track->interpolation;
                int input = sampler["input"].get<int>();
                if (a != home || track == &zeros) {
                    // Our targets stay at 0 while it plays (the first frame's lighting).
                    const size_t groups = interpolation == Interpolation::CubicSpline ? 3 : 1;
                    for (size_t k = 0; k < keys.size(); ++k)
                        for (size_t g = 0; g < groups; ++g) {
                            for (size_t i = 0; i < own; ++i) values.push_back(float(track->values[(k * groups + g) * own + i]));
                            values.insert(values.end(), lighting, 0.0f);
                        }
                    if (a == home) continue;  // replaced below by the lighting's own channel
                } else {
                    // Its keys and the frames' merged. A cubic spline is resampled LINEAR there
                    // (exact at the keys); a LINEAR sampler gains a key just before each frame so
                    // that the lighting steps rather than fades.
                    drivenInHome = true;
                    if (interpolation == Interpolation::CubicSpline) {
                        warnings.add(file + ": animations[" + std::to_string(a) + "]'s cubic-spline weights on nodes[" +
                                     std::to_string(node) + "] are written LINEAR between their keys and the frames");
                        interpolation = Interpolation::Linear;
                    }
                    keys.insert(keys.end(), frameTimes.begin(), frameTimes.end());
                    if (interpolation == Interpolation::Linear)
                        for (size_t k = 1; k < frames; ++k) {
                            const float before = frameTimes[k] - 1e-3f * (frameTimes[k] - frameTimes[k - 1]);
                            if (before > frameTimes[k - 1] && before < frameTimes[k]) keys.push_back(before);
                        }
                    std::sort(keys.begin(), keys.end());
                    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
                    std::vector<double> sampled(std::max<size_t>(own, 1));
                    for (const float t : keys) {
                        track->sample(double(t), false, sampled.data());
                        for (size_t i = 0; i < own; ++i) values.push_back(float(sampled[i]));
                        oneHot(frameAtTime(t), values);
                    }
                    input = bin.addScalars(keys, true);
                }
                channel["sampler"] = addSampler(animation, input, addWeights(values), interpolation);
            }
        }
        if (!drivenInHome) {
            // A channel of its own, or (a channel the loader did not keep, in its animation) in
            // place of that one: the node's weights are driven once an animation.
            std::vector<float> values;
            for (size_t f = 0; f < frames; ++f) {
                for (size_t i = 0; i < own; ++i) values.push_back(float(rest[i]));
                oneHot(f, values);
            }
            json& animation = animations[home];
            const int sampler = addSampler(animation, frameTimesIndex(), addWeights(values), Interpolation::Step);
            bool replaced = false;
            for (json& c : animation["channels"])
                if (c.contains("target") && c["target"].value("node", -1) == node && c["target"].value("path", "") == "weights") {
                    c["sampler"] = sampler;
                    replaced = true;
                }
            if (!replaced) animation["channels"].push_back({{"sampler", sampler}, {"target", {{"node", node}, {"path", "weights"}}}});
        }
    }
    // glTF forbids an animation without channels, and an empty list of them.
    if (animations.size() > fileAnimations && animations.back()["channels"].empty()) animations.erase(animations.size() - 1);
    if (animations.empty()) doc.erase("animations");
}

void giveFirstPose(json& doc, const std::vector<Transform>& firstPose) {
    for (size_t n = 0; n < firstPose.size() && doc.contains("nodes") && n < doc["nodes"].size(); ++n) {
        const Transform given = nodeTransform(doc["nodes"][n]);
        double largest = 1, difference = 0;
        for (int i = 0; i < 16; ++i) {
            largest = std::max(largest, std::fabs(given.m[size_t(i)]));
            difference = std::max(difference, std::fabs(given.m[size_t(i)] - firstPose[n].m[size_t(i)]));
        }
        if (difference > 1e-12 * largest) setNodeTrs(doc["nodes"][n], decomposeTrs(firstPose[n]));
    }
}

}  // namespace qsgi
