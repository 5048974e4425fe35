#include "output/glb_writer.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>


namespace qsgi {
namespace {

// Appends `elements` records of `elementBytes` (filled by `write(i, destination)`) to the buffer
// as a new buffer view; returns its index.
template <typename Write>
int appendBufferView(tinygltf::Model& model, size_t elements, size_t elementBytes, int target, Write write) {
    tinygltf::Buffer& buffer = model.buffers[0];
    const size_t offset = buffer.data.size();
    buffer.data.resize(offset + elements * elementBytes);
    for (size_t i = 0; i < elements; ++i) write(i, &buffer.data[offset + i * elementBytes]);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = offset;
    view.byteLength = elements * elementBytes;
    view.target = target;
    model.bufferViews.push_back(view);
    return int(model.bufferViews.size()) - 1;
}

// Appends VEC3 floats as a buffer view and an accessor; returns the accessor's index.
int addVec3Accessor(tinygltf::Model& model, const std::vector<Vec3f>& values, bool withBounds) {
    tinygltf::Accessor accessor;
    accessor.bufferView = appendBufferView(model, values.size(), 12, TINYGLTF_TARGET_ARRAY_BUFFER,
                                           [&](size_t i, unsigned char* out) {
                                               const float xyz[3] = {values[i].x, values[i].y, values[i].z};
                                               std::memcpy(out, xyz, 12);
                                           });
    accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    accessor.type = TINYGLTF_TYPE_VEC3;
    accessor.count = values.size();
    if (withBounds) {  // glTF requires them on POSITION
        Bounds3f b;
        for (const Vec3f& v : values) b.extend(v);
        accessor.minValues = {b.lower.x, b.lower.y, b.lower.z};
        accessor.maxValues = {b.upper.x, b.upper.y, b.upper.z};
    }
    model.accessors.push_back(accessor);
    return int(model.accessors.size()) - 1;
}

int addIndexAccessor(tinygltf::Model& model, const std::vector<Triangle>& triangles) {
    tinygltf::Accessor accessor;
    accessor.bufferView = appendBufferView(model, triangles.size(), 12, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER,
                                           [&](size_t t, unsigned char* out) { std::memcpy(out, triangles[t].v, 12); });
    accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    accessor.type = TINYGLTF_TYPE_SCALAR;
    accessor.count = triangles.size() * 3;
    model.accessors.push_back(accessor);
    return int(model.accessors.size()) - 1;
}

}  // namespace

std::string encodeVertexRadiosityGlb(const Scene& scene, const VertexRadiosity& result, const PreviewTonemap& tonemap) {
    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = std::string("qsgi ") + QSGI_VERSION;
    model.buffers.resize(1);
    model.extensionsUsed = {"KHR_materials_unlit"};

    // The tonemap maps radiosity B to white at scale·B = 1, so radiance B/π at exposure π·scale.
    const double exposure = M_PI * double(tonemap.scale);
    std::vector<Vec3f> radiance(result.radiosity.size()), colour(result.radiosity.size());
    for (size_t v = 0; v < radiance.size(); ++v) {
        radiance[v] = result.radiosity[v] * float(1 / M_PI);
        for (int c = 0; c < 3; ++c) colour[v][c] = float(std::clamp(double(radiance[v][c]) * exposure, 0.0, 1.0));
    }
    tinygltf::Primitive primitive;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    primitive.attributes["POSITION"] = addVec3Accessor(model, scene.positions, true);
    primitive.attributes["NORMAL"] = addVec3Accessor(model, scene.normals, false);
    primitive.attributes["COLOR_0"] = addVec3Accessor(model, colour, false);
    primitive.attributes["_RADIANCE"] = addVec3Accessor(model, radiance, false);
    primitive.attributes["_IRRADIANCE"] = addVec3Accessor(model, result.irradiance, false);
    primitive.indices = addIndexAccessor(model, scene.triangles);
    primitive.material = 0;

    tinygltf::Material material;
    material.name = "qsgi radiance (unlit: COLOR_0 = B/pi)";
    material.pbrMetallicRoughness.baseColorFactor = {1, 1, 1, 1};
    material.pbrMetallicRoughness.metallicFactor = 0;
    material.extensions["KHR_materials_unlit"] = tinygltf::Value(tinygltf::Value::Object());
    model.materials.push_back(material);

    tinygltf::Mesh mesh;
    mesh.name = "scene";
    tinygltf::Value::Object qsgi;
    qsgi["exposure"] = tinygltf::Value(exposure);
    qsgi["color"] = tinygltf::Value(std::string("COLOR_0 = min(1, exposure * _RADIANCE)"));
    qsgi["units"] = tinygltf::Value(std::string("_RADIANCE: W m^-2 sr^-1 (B/pi); _IRRADIANCE: W m^-2"));
    tinygltf::Value::Object extras;
    extras["qsgi"] = tinygltf::Value(qsgi);
    mesh.extras = tinygltf::Value(extras);
    mesh.primitives.push_back(primitive);
    model.meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = "qsgi frame";
    node.mesh = 0;
    // Positions are relative to worldOrigin (see Scene): the node puts them back in place.
    if (!(scene.worldOrigin == Vec3d(0.0)))
        node.translation = {scene.worldOrigin.x, scene.worldOrigin.y, scene.worldOrigin.z};
    model.nodes.push_back(node);
    tinygltf::Scene root;
    root.nodes = {0};
    model.scenes.push_back(root);
    model.defaultScene = 0;

    std::ostringstream bytes;
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, bytes, false, true))
        throw std::runtime_error("tinygltf could not encode a frame's GLB");
    return bytes.str();
}

}  // namespace qsgi
