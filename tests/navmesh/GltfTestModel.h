#pragma once

// The start of the glTF models the navmesh tests write: an inSide m square at y = 0 (counter-clockwise seen
// from above) in one buffer, with accessor 0 its four positions and accessor 1 its six indices (two
// triangles, unsigned short) on buffer views 0 and 1. The tests add meshes, materials, nodes and a scene.

#include <cstring>
#include <tiny_gltf.h>

namespace cairn::navmesh::test
{

inline tinygltf::Model SquareModel(float inSide)
{
    const float positions[] = {0, 0, 0, 0, 0, inSide, inSide, 0, inSide, inSide, 0, 0};
    const uint16_t indices[] = {0, 1, 2, 0, 2, 3};
    tinygltf::Model model;
    tinygltf::Buffer buffer;
    buffer.data.resize(sizeof(positions) + sizeof(indices));
    std::memcpy(buffer.data.data(), positions, sizeof(positions));
    std::memcpy(buffer.data.data() + sizeof(positions), indices, sizeof(indices));
    model.buffers.push_back(buffer);
    tinygltf::BufferView positionView, indexView;
    positionView.buffer = 0;
    positionView.byteLength = sizeof(positions);
    indexView.buffer = 0;
    indexView.byteOffset = sizeof(positions);
    indexView.byteLength = sizeof(indices);
    model.bufferViews = {positionView, indexView};
    tinygltf::Accessor positionAccessor, indexAccessor;
    positionAccessor.bufferView = 0;
    positionAccessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    positionAccessor.type = TINYGLTF_TYPE_VEC3;
    positionAccessor.count = 4;
    positionAccessor.minValues = {0, 0, 0};
    positionAccessor.maxValues = {inSide, 0, inSide};
    indexAccessor.bufferView = 1;
    indexAccessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    indexAccessor.type = TINYGLTF_TYPE_SCALAR;
    indexAccessor.count = 6;
    model.accessors = {positionAccessor, indexAccessor};
    model.asset.version = "2.0";
    return model;
}

} // namespace cairn::navmesh::test
