#include "scene/gltf_animation.h"

#include <cmath>
#include <set>
#include <utility>

namespace qsgi {
namespace {

// Output formats per property (glTF 2.0 §3.11, table "Animation sampler output").
const std::vector<std::pair<int, bool>> kFloat = {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}};
const std::vector<std::pair<int, bool>> kFloatOrNormalized = {
    {TINYGLTF_COMPONENT_TYPE_FLOAT, false},         {TINYGLTF_COMPONENT_TYPE_BYTE, true},
    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true},  {TINYGLTF_COMPONENT_TYPE_SHORT, true},
    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true}};
const AccessorFormat kTimeFormat{TINYGLTF_TYPE_SCALAR, kFloat, {}};

AccessorFormat outputFormat(AnimatedProperty p) {
    switch (p) {
        case AnimatedProperty::Translation:
        case AnimatedProperty::Scale: return {TINYGLTF_TYPE_VEC3, kFloat, {}};
        case AnimatedProperty::Rotation: return {TINYGLTF_TYPE_VEC4, kFloatOrNormalized, {}};
        case AnimatedProperty::Weights: return {TINYGLTF_TYPE_SCALAR, kFloatOrNormalized, {}};
    }
    return {};
}

bool parseProperty(const std::string& path, AnimatedProperty& out) {
    if (path == "translation") out = AnimatedProperty::Translation;
    else if (path == "rotation") out = AnimatedProperty::Rotation;
    else if (path == "scale") out = AnimatedProperty::Scale;
    else if (path == "weights") out = AnimatedProperty::Weights;
    else return false;
    return true;
}

bool parseInterpolation(const std::string& name, Interpolation& out) {
    if (name == "LINEAR") out = Interpolation::Linear;
    else if (name == "STEP") out = Interpolation::Step;
    else if (name == "CUBICSPLINE") out = Interpolation::CubicSpline;
    else return false;
    return true;
}

// The number of morph targets a node's mesh has (every primitive must have the same number).
size_t morphTargetCount(const tinygltf::Model& model, int node) {
    const int mesh = model.nodes[size_t(node)].mesh;
    if (mesh < 0 || mesh >= int(model.meshes.size()) || model.meshes[size_t(mesh)].primitives.empty()) return 0;
    return model.meshes[size_t(mesh)].primitives[0].targets.size();
}

}  // namespace

std::vector<KeyframeAnimation> readGltfAnimations(const tinygltf::Model& model, const AccessorReader& reader,
                                                  const std::string& file, Warnings& warnings) {
    std::vector<KeyframeAnimation> out;
    for (size_t a = 0; a < model.animations.size(); ++a) {
        const tinygltf::Animation& source = model.animations[a];
        const std::string animationPlace = gltfPlace("animations", int(a));
        KeyframeAnimation animation;
        animation.name = source.name.empty() ? "animation " + std::to_string(a) : source.name;
        if (source.channels.empty())  // kept, so that gltf:N still names the file's animation N
            warnings.add(file + ": " + animationPlace + " has no channels (glTF requires at least one): it moves nothing");
        std::set<std::pair<int, AnimatedProperty>> targets;
        bool first = true;
        for (size_t c = 0; c < source.channels.size(); ++c) {
            const tinygltf::AnimationChannel& ch = source.channels[c];
            const std::string place = animationPlace + "." + gltfPlace("channels", int(c));
            if (ch.target_node < 0) {
                warnings.add(file + ": " + place + " has no target node (an extension's channel); skipped");
                continue;
            }
            if (ch.target_node >= int(model.nodes.size()))
                throw InputError(file, place + ".target.node",
                                 "refers to node " + std::to_string(ch.target_node) + ", which does not exist");
            AnimationChannel channel;
            channel.node = ch.target_node;
            if (!parseProperty(ch.target_path, channel.property))
                throw InputError(file, place + ".target.path",
                                 "'" + ch.target_path + "' is not translation, rotation, scale or weights");
            if (!targets.insert({channel.node, channel.property}).second)
                throw InputError(file, place, std::string("animates the ") + animatedPropertyName(channel.property) +
                                                  " of node " + std::to_string(channel.node) +
                                                  ", which another channel of the animation already animates");
            const tinygltf::Node& node = model.nodes[size_t(channel.node)];
            if (node.matrix.size() == 16 && channel.property != AnimatedProperty::Weights)
                throw InputError(file, place, "targets node " + std::to_string(channel.node) +
                                                  ", which has a matrix; an animated node must use translation, "
                                                  "rotation and scale");
            if (ch.sampler < 0 || ch.sampler >= int(source.samplers.size()))
                throw InputError(file, place + ".sampler",
                                 "refers to sampler " + std::to_string(ch.sampler) + ", which does not exist");
            const tinygltf::AnimationSampler& sampler = source.samplers[size_t(ch.sampler)];
            const std::string samplerPlace = animationPlace + "." + gltfPlace("samplers", ch.sampler);
            KeyframeTrack& track = channel.track;
            if (!parseInterpolation(sampler.interpolation, track.interpolation))
                throw InputError(file, samplerPlace + ".interpolation",
                                 "'" + sampler.interpolation + "' is not LINEAR, STEP or CUBICSPLINE");

            const AccessorData input = reader.read(sampler.input, samplerPlace + ".input", kTimeFormat);
            if (input.count == 0) throw InputError(file, samplerPlace + ".input", "has no key times");
            if (track.interpolation == Interpolation::CubicSpline && input.count < 2)
                throw InputError(file, samplerPlace + ".input", "has 1 key; CUBICSPLINE needs at least 2 (glTF 2.0)");
            // glTF 2.0 (§5.1.3): an animation input accessor states its bounds, as POSITION does.
            const tinygltf::Accessor& times = model.accessors[size_t(sampler.input)];
            if (times.minValues.size() != 1 || times.maxValues.size() != 1)
                throw InputError(file, gltfPlace("accessors", sampler.input),
                                 "is an animation input without min and max (glTF requires both)");
            // An input accessor without a bufferView or sparse values holds zeros by default: valid
            // glTF (the validator has no elements to check), but keys all at 0 s animate nothing.
            // The channel is checked like any other and then left out, with a warning.
            const bool timesStated = reader.hasData(sampler.input);
            for (size_t k = 0; timesStated && k < input.count; ++k) {
                if (input.values[k] < 0)
                    throw InputError(file, samplerPlace + ".input", "key time " + std::to_string(input.values[k]) +
                                                                        " is negative");
                if (k > 0 && !(input.values[k] > input.values[k - 1]))
                    throw InputError(file, samplerPlace + ".input",
                                     "key times must strictly increase (key " + std::to_string(k) + " at " +
                                         std::to_string(input.values[k]) + " s follows " +
                                         std::to_string(input.values[k - 1]) + " s)");
            }
            track.times = input.values;

            const AccessorData output =
                reader.read(sampler.output, samplerPlace + ".output", outputFormat(channel.property));
            size_t perKey = size_t(output.components);
            if (channel.property == AnimatedProperty::Weights) {
                perKey = morphTargetCount(model, channel.node);
                if (perKey == 0)
                    throw InputError(file, place, "animates the morph weights of node " +
                                                      std::to_string(channel.node) +
                                                      ", whose mesh has no morph targets");
            }
            const size_t groups = track.interpolation == Interpolation::CubicSpline ? 3 : 1;
            const size_t expected = input.count * groups * perKey;
            if (output.values.size() != expected)
                throw InputError(file, samplerPlace + ".output",
                                 "holds " + std::to_string(output.values.size()) + " numbers; " +
                                     std::to_string(input.count) + " keys of " + interpolationName(track.interpolation) +
                                     " " + animatedPropertyName(channel.property) + " need " + std::to_string(expected));
            track.components = int(perKey);
            track.values = output.values;
            // Keys are judged where the file states them; a channel with an input or output of
            // default zeros is left out below.
            const bool keysStated = timesStated && reader.hasData(sampler.output);
            if (channel.property == AnimatedProperty::Rotation && reader.hasData(sampler.output))
                for (size_t k = 0; k < input.count; ++k) {
                    const double* q = &track.values[(k * groups + (groups == 3 ? 1 : 0)) * 4];
                    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
                    if (!(norm > 1e-6))
                        throw InputError(file, samplerPlace + ".output",
                                         "key " + std::to_string(k) + " is a zero quaternion, which is no rotation");
                    // Unit, within the glTF-Validator's tolerance.
                    if (!(std::fabs(norm - 1) <= kUnitQuaternionTolerance))
                        throw InputError(file, samplerPlace + ".output", "key " + std::to_string(k) + " has length " +
                                                                             std::to_string(norm) + ", not 1 (a rotation is a unit quaternion)");
                }
            if (!keysStated) {
                warnings.add(file + ": " + samplerPlace + (timesStated ? ".output" : ".input") +
                             " has no data (an accessor without a bufferView holds zeros), so " + place +
                             " animates nothing and is left out");
                continue;
            }
            animation.startTime = first ? track.times.front() : std::min(animation.startTime, track.times.front());
            animation.endTime = first ? track.times.back() : std::max(animation.endTime, track.times.back());
            first = false;
            animation.channels.push_back(std::move(channel));
        }
        out.push_back(std::move(animation));
    }
    return out;
}

}  // namespace qsgi
