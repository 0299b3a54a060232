#include "cairn/navmesh/ObjMesh.h"

#include <Eigen/Geometry>
#include <array>
#include <cstring>
#include <filesystem>
#include <tiny_gltf.h>

namespace cairn::navmesh
{

namespace
{
using Mat4 = Eigen::Matrix4d;

/// A node's local transform: its matrix, or translation * rotation * scale.
Mat4 LocalTransform(const tinygltf::Node& inNode)
{
    Mat4 m = Mat4::Identity();
    if (inNode.matrix.size() == 16)
    {
        for (int i = 0; i < 16; ++i)
            m(i % 4, i / 4) = inNode.matrix[size_t(i)]; // Column-major
        return m;
    }
    if (inNode.translation.size() == 3)
        m.block<3, 1>(0, 3) =
            Eigen::Vector3d(inNode.translation[0], inNode.translation[1], inNode.translation[2]);
    Mat4 rotation = Mat4::Identity();
    if (inNode.rotation.size() == 4)
        rotation.block<3, 3>(0, 0) =
            Eigen::Quaterniond(inNode.rotation[3], inNode.rotation[0], inNode.rotation[1], inNode.rotation[2])
                .normalized()
                .toRotationMatrix();
    Mat4 scale = Mat4::Identity();
    if (inNode.scale.size() == 3)
        scale.diagonal().head<3>() = Eigen::Vector3d(inNode.scale[0], inNode.scale[1], inNode.scale[2]);
    return m * rotation * scale;
}

class GltfReader
{
public:
    GltfReader(const std::string& inPath, const tinygltf::Model& inModel) : mPath(inPath), mModel(inModel)
    {
        for (size_t i = 0; i < inModel.materials.size(); ++i)
            mMesh.mMaterials.push_back(!inModel.materials[i].name.empty()
                                           ? inModel.materials[i].name
                                           : "materials[" + std::to_string(i) + "]");
    }

    Status AddNode(int inNode, const Mat4& inParent, int inDepth)
    {
        if (inNode < 0 || size_t(inNode) >= mModel.nodes.size() || inDepth > 64)
            return Fail("nodes[" + std::to_string(inNode) + "]", "does not exist or nests too deep");
        const tinygltf::Node& node = mModel.nodes[size_t(inNode)];
        const Mat4 world = inParent * LocalTransform(node);
        if (node.mesh >= 0)
        {
            // Each node with a mesh is an object of its own (instances of one mesh included)
            MeshObject object{!node.name.empty() ? node.name : "nodes[" + std::to_string(inNode) + "]",
                              uint32_t(mMesh.mTriangles.size()), 0};
            if (Status added = AddMesh(node.mesh, world); !added) return added;
            object.mNumTriangles = uint32_t(mMesh.mTriangles.size()) - object.mFirstTriangle;
            if (object.mNumTriangles > 0) mMesh.mObjects.push_back(std::move(object));
        }
        for (int child : node.children)
            if (Status added = AddNode(child, world, inDepth + 1); !added) return added;
        return Status::Ok();
    }

    IndexedMesh mMesh;

private:
    Status Fail(const std::string& inElement, const std::string& inWhat) const
    {
        return MakeError(ErrorCode::ParseError, mPath + ": " + inElement + ": " + inWhat);
    }

    /// The bytes of an accessor's elements, checked against its buffer view and buffer.
    Status Elements(int inAccessor, int inComponentType, int inType, std::vector<double>& outValues) const
    {
        const std::string where = "accessors[" + std::to_string(inAccessor) + "]";
        if (inAccessor < 0 || size_t(inAccessor) >= mModel.accessors.size())
            return Fail(where, "does not exist");
        const tinygltf::Accessor& accessor = mModel.accessors[size_t(inAccessor)];
        if (inType >= 0 && accessor.type != inType) return Fail(where, "has the wrong type");
        if (inComponentType >= 0 && accessor.componentType != inComponentType)
            return Fail(where, "has the wrong component type");
        if (accessor.bufferView < 0 || size_t(accessor.bufferView) >= mModel.bufferViews.size())
            return Fail(where, "has no buffer view (sparse accessors are not supported)");
        const tinygltf::BufferView& view = mModel.bufferViews[size_t(accessor.bufferView)];
        if (view.buffer < 0 || size_t(view.buffer) >= mModel.buffers.size()) return Fail(where, "bad buffer");
        const std::vector<unsigned char>& buffer = mModel.buffers[size_t(view.buffer)].data;
        const int components = tinygltf::GetNumComponentsInType(uint32_t(accessor.type));
        const int componentSize = tinygltf::GetComponentSizeInBytes(uint32_t(accessor.componentType));
        if (components <= 0 || componentSize <= 0) return Fail(where, "unknown type");
        const size_t elementSize = size_t(components) * size_t(componentSize);
        const size_t stride = view.byteStride != 0 ? view.byteStride : elementSize;
        // Offsets, lengths and counts come from the file: compared by subtraction from what is known to fit,
        // never summed or multiplied, where a hostile value would wrap around and pass (a count of 2^62, an
        // offset near 2^64)
        if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset)
            return Fail(where, "has a buffer view beyond its buffer");
        if (accessor.count > 0 &&
            (accessor.byteOffset > view.byteLength || elementSize > view.byteLength - accessor.byteOffset ||
             accessor.count - 1 > (view.byteLength - accessor.byteOffset - elementSize) / stride))
            return Fail(where, "reads beyond its buffer");
        const size_t start = view.byteOffset + accessor.byteOffset; // Both inside the buffer: no wrap
        outValues.clear();
        for (size_t i = 0; i < accessor.count; ++i)
            for (int c = 0; c < components; ++c)
            {
                const unsigned char* p = buffer.data() + start + i * stride + size_t(c * componentSize);
                switch (accessor.componentType)
                {
                case TINYGLTF_COMPONENT_TYPE_FLOAT:
                {
                    float v;
                    std::memcpy(&v, p, 4);
                    outValues.push_back(v);
                    break;
                }
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
                    outValues.push_back(*p);
                    break;
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
                {
                    uint16_t v;
                    std::memcpy(&v, p, 2);
                    outValues.push_back(v);
                    break;
                }
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
                {
                    uint32_t v;
                    std::memcpy(&v, p, 4);
                    outValues.push_back(v);
                    break;
                }
                default:
                    return Fail(where, "has a component type a level mesh cannot use");
                }
            }
        return Status::Ok();
    }

    Status AddMesh(int inMesh, const Mat4& inWorld)
    {
        if (size_t(inMesh) >= mModel.meshes.size())
            return Fail("meshes[" + std::to_string(inMesh) + "]", "does not exist");
        const tinygltf::Mesh& mesh = mModel.meshes[size_t(inMesh)];
        for (size_t p = 0; p < mesh.primitives.size(); ++p)
        {
            const tinygltf::Primitive& primitive = mesh.primitives[p];
            const std::string where =
                "meshes[" + std::to_string(inMesh) + "].primitives[" + std::to_string(p) + "]";
            if (primitive.mode != TINYGLTF_MODE_TRIANGLES && primitive.mode != -1)
                continue; // Lines, points: no floor
            auto position = primitive.attributes.find("POSITION");
            if (position == primitive.attributes.end()) return Fail(where, "has no POSITION");
            std::vector<double> positions, indices;
            if (Status read =
                    Elements(position->second, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, positions);
                !read)
                return read;
            const uint32_t first = uint32_t(mMesh.mVertices.size());
            for (size_t i = 0; i + 2 < positions.size(); i += 3)
            {
                const Eigen::Vector4d v =
                    inWorld * Eigen::Vector4d(positions[i], positions[i + 1], positions[i + 2], 1.0);
                const Vec3 world(float(v.x()), float(v.y()), float(v.z()));
                if (!IsValidWorldPosition(world))
                    return Fail(where, "has a vertex that is not finite or out of range");
                mMesh.mVertices.push_back(world);
            }
            const uint32_t count = uint32_t(positions.size() / 3);
            if (primitive.indices >= 0)
            {
                if (Status read = Elements(primitive.indices, -1, TINYGLTF_TYPE_SCALAR, indices); !read)
                    return read;
            }
            else
                for (uint32_t i = 0; i < count; ++i)
                    indices.push_back(i);
            // A mirroring transform turns the winding: keep triangles counter-clockwise seen from their front
            const bool mirrored = inWorld.block<3, 3>(0, 0).determinant() < 0.0;
            if (primitive.material >= int(mModel.materials.size()))
                return Fail(where, "names material " + std::to_string(primitive.material) + " of " +
                                       std::to_string(mModel.materials.size()));
            const uint32_t material =
                primitive.material >= 0 ? uint32_t(primitive.material) : IndexedMesh::cNoMaterial;
            for (size_t i = 0; i + 2 < indices.size(); i += 3)
            {
                std::array<uint32_t, 3> triangle;
                for (int k = 0; k < 3; ++k)
                {
                    if (indices[i + size_t(k)] >= count)
                        return Fail(where, "has an index beyond its vertices");
                    triangle[size_t(k)] = first + uint32_t(indices[i + size_t(k)]);
                }
                if (mirrored) std::swap(triangle[1], triangle[2]);
                mMesh.mTriangles.push_back(triangle);
                mMesh.mTriangleMaterials.push_back(material);
            }
        }
        return Status::Ok();
    }

    const std::string& mPath;
    const tinygltf::Model& mModel;
};
} // namespace

Result<IndexedMesh> LoadGltfMesh(const std::string& inPath)
{
    std::error_code error;
    if (!std::filesystem::is_regular_file(inPath, error))
        return MakeError(ErrorCode::IOError, inPath + ": not a readable file");
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string errors, warnings;
    const bool binary = std::filesystem::path(inPath).extension() == ".glb";
    const bool loaded = binary ? loader.LoadBinaryFromFile(&model, &errors, &warnings, inPath)
                               : loader.LoadASCIIFromFile(&model, &errors, &warnings, inPath);
    if (!loaded)
        return MakeError(ErrorCode::ParseError, inPath + ": " + (errors.empty() ? "malformed glTF" : errors));
    GltfReader reader(inPath, model);
    std::vector<int> roots;
    if (model.defaultScene >= 0 && size_t(model.defaultScene) < model.scenes.size())
        roots = model.scenes[size_t(model.defaultScene)].nodes;
    else if (!model.scenes.empty())
        roots = model.scenes.front().nodes;
    else
        for (size_t i = 0; i < model.nodes.size(); ++i)
            roots.push_back(int(i));
    for (int node : roots)
        if (Status added = reader.AddNode(node, Mat4::Identity(), 0); !added) return added.GetError();
    if (reader.mMesh.mTriangles.empty()) return MakeError(ErrorCode::ParseError, inPath + ": no triangles");
    return std::move(reader.mMesh);
}

Result<IndexedMesh> LoadLevelMesh(const std::string& inPath)
{
    const std::string extension = std::filesystem::path(inPath).extension().string();
    if (extension == ".gltf" || extension == ".glb") return LoadGltfMesh(inPath);
    if (extension == ".obj" || extension == ".OBJ") return LoadObjMesh(inPath);
    return MakeError(ErrorCode::InvalidArgument,
                     inPath + ": unknown level format (expected .obj, .gltf or .glb)");
}

} // namespace cairn::navmesh
