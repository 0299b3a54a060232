#include "LevelFileAccess.h"
#include "cairn/navmesh/LevelMesh.h"

#include <Eigen/Geometry>
#include <array>
#include <cstring>
#include <filesystem>
#include <tiny_gltf.h>

namespace cairn::navmesh
{
using namespace cairn::physics;

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
    GltfReader(const std::string& inPath, const tinygltf::Model& inModel, const LevelLoadLimits& inLimits)
        : mPath(inPath), mModel(inModel), mLimits(inLimits), mReached(inModel.nodes.size(), false)
    {
        for (size_t i = 0; i < inModel.materials.size(); ++i)
            mMesh.mMaterials.push_back(!inModel.materials[i].name.empty()
                                           ? inModel.materials[i].name
                                           : "materials[" + std::to_string(i) + "]");
    }

    /// The node inRoot and the tree under it, depth first (children in order), without recursion.
    Status AddTree(int inRoot)
    {
        struct Pending
        {
            int mNode;
            Mat4 mParent;
            uint32_t mDepth;
        };
        std::vector<Pending> pending{{inRoot, Mat4::Identity(), 0}};
        while (!pending.empty())
        {
            const Pending next = pending.back();
            pending.pop_back();
            const std::string where = "nodes[" + std::to_string(next.mNode) + "]";
            if (next.mNode < 0 || size_t(next.mNode) >= mModel.nodes.size())
                return Fail(where, "does not exist");
            if (next.mDepth > mLimits.mMaxNodeDepth)
                return Fail(where, "is deeper than " + std::to_string(mLimits.mMaxNodeDepth) +
                                       " nodes (LevelLoadLimits::mMaxNodeDepth)");
            // glTF's nodes form trees: a node reached twice is under two parents, or its own ancestor, and
            // graphs that share nodes multiply (a 40-level diamond is 2^40 instances)
            if (mReached[size_t(next.mNode)])
                return Fail(where, "is reached a second time: a glTF node has one parent at most");
            mReached[size_t(next.mNode)] = true;
            const tinygltf::Node& node = mModel.nodes[size_t(next.mNode)];
            const Mat4 world = next.mParent * LocalTransform(node);
            if (node.mesh >= 0)
            {
                // Each node with a mesh is an object of its own (instances of one mesh included)
                MeshObject object{!node.name.empty() ? node.name : where, uint32_t(mMesh.mTriangles.size()),
                                  0};
                if (Status added = AddMesh(node.mesh, world); !added) return added;
                object.mNumTriangles = uint32_t(mMesh.mTriangles.size()) - object.mFirstTriangle;
                if (object.mNumTriangles > 0) mMesh.mObjects.push_back(std::move(object));
            }
            for (auto child = node.children.rbegin(); child != node.children.rend(); ++child)
                pending.push_back({*child, world, next.mDepth + 1});
        }
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
            if (positions.size() / 3 > mLimits.mMaxVertices - mMesh.mVertices.size())
                return Fail(where, "brings the level over " + std::to_string(mLimits.mMaxVertices) +
                                       " vertices (LevelLoadLimits::mMaxVertices)");
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
            if (indices.size() / 3 > mLimits.mMaxTriangles - mMesh.mTriangles.size())
                return Fail(where, "brings the level over " + std::to_string(mLimits.mMaxTriangles) +
                                       " triangles (LevelLoadLimits::mMaxTriangles)");
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
    const LevelLoadLimits& mLimits;
    std::vector<bool> mReached; ///< Per node
};
} // namespace

namespace
{
/// tinygltf's file access for one level: files only from the level's folder (unless the limits allow more),
/// regular files only, within the byte limit, and never a write.
struct GltfFileAccess
{
    std::filesystem::path mFolder;
    const LevelLoadLimits& mLimits;

    static bool FileExists(const std::string& inPath, void* inAccess)
    {
        // A file outside the folder "exists": its read is refused with a message that says why, and the
        // answer tells nothing of the files there
        const auto& access = *static_cast<const GltfFileAccess*>(inAccess);
        std::error_code error;
        return !access.Allows(inPath) || std::filesystem::exists(inPath, error);
    }

    /// The URI as the file gives it: tinygltf's default expands it as a shell word ($HOME, ~)
    static std::string ExpandFilePath(const std::string& inPath, void*) { return inPath; }

    static bool ReadWholeFile(std::vector<unsigned char>* outBytes, std::string* outError,
                              const std::string& inPath, void* inAccess)
    {
        const auto& access = *static_cast<const GltfFileAccess*>(inAccess);
        if (!access.Allows(inPath))
        {
            *outError = "outside the level's folder (LevelLoadLimits::mAllowFilesOutsideFolder)";
            return false;
        }
        Result<std::vector<unsigned char>> bytes = ReadLevelFile(inPath, access.mLimits.mMaxFileBytes);
        if (!bytes)
        {
            *outError = bytes.GetError().mMessage;
            return false;
        }
        *outBytes = std::move(bytes.Value());
        return true;
    }

    static bool RefuseWrite(std::string* outError, const std::string&, const std::vector<unsigned char>&,
                            void*)
    {
        *outError = "a level load writes no file";
        return false;
    }

    bool Allows(const std::string& inPath) const
    {
        return mLimits.mAllowFilesOutsideFolder || IsInsideFolder(inPath, mFolder);
    }
};

/// Images are texture, not floor: never decoded (a 16384^2 PNG took 27 s and 2 GB)
bool SkipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
               void*)
{
    return true;
}

/// The JSON chunk of a .glb, or empty when the container is malformed (tinygltf then says how).
std::string_view GlbJson(const std::vector<unsigned char>& inBytes)
{
    if (inBytes.size() < 20) return {};
    uint32_t length = 0;
    std::memcpy(&length, inBytes.data() + 12, 4);
    if (length > inBytes.size() - 20) return {};
    return {reinterpret_cast<const char*>(inBytes.data() + 20), length};
}
} // namespace

Result<IndexedMesh> LoadGltfMesh(const std::string& inPath, const LevelLoadLimits& inLimits)
{
    Result<std::vector<unsigned char>> bytes =
        ReadLevelFile(inPath, std::min<uint64_t>(inLimits.mMaxFileBytes, 0xffffffffu));
    if (!bytes) return bytes.GetError();
    const std::vector<unsigned char>& file = bytes.Value();
    const bool binary = LowerCaseExtension(inPath) == ".glb";
    // tinygltf converts extras and extensions recursively: nesting 100,000 deep overflowed the stack
    const std::string_view json =
        binary ? GlbJson(file) : std::string_view(reinterpret_cast<const char*>(file.data()), file.size());
    if (JsonNestingDepth(json, inLimits.mMaxNesting) > inLimits.mMaxNesting)
        return MakeError(ErrorCode::ParseError, inPath + ": JSON nests deeper than " +
                                                    std::to_string(inLimits.mMaxNesting) +
                                                    " (LevelLoadLimits::mMaxNesting)");
    const std::filesystem::path folder = std::filesystem::path(inPath).parent_path();
    GltfFileAccess access{folder.empty() ? std::filesystem::path(".") : folder, inLimits};
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(&SkipImage, nullptr);
    loader.SetFsCallbacks({&GltfFileAccess::FileExists, &GltfFileAccess::ExpandFilePath,
                           &GltfFileAccess::ReadWholeFile, &GltfFileAccess::RefuseWrite, &access});
    tinygltf::Model model;
    std::string errors, warnings;
    bool loaded = false;
    try
    {
        loaded = binary ? loader.LoadBinaryFromMemory(&model, &errors, &warnings, file.data(),
                                                      unsigned(file.size()), access.mFolder.string())
                        : loader.LoadASCIIFromString(&model, &errors, &warnings,
                                                     reinterpret_cast<const char*>(file.data()),
                                                     unsigned(file.size()), access.mFolder.string());
    }
    catch (const std::exception& exception)
    {
        // tinygltf's JSON library and allocations throw: a file is an error, never an abort
        return MakeError(ErrorCode::ParseError, inPath + ": the glTF parser failed: " + exception.what());
    }
    if (!loaded)
        return MakeError(ErrorCode::ParseError, inPath + ": " + (errors.empty() ? "malformed glTF" : errors));
    GltfReader reader(inPath, model, inLimits);
    std::vector<int> roots;
    if (model.defaultScene >= 0 && size_t(model.defaultScene) < model.scenes.size())
        roots = model.scenes[size_t(model.defaultScene)].nodes;
    else if (!model.scenes.empty())
        roots = model.scenes.front().nodes;
    else
    {
        // No scene: every tree of nodes, from the nodes that are no one's child
        std::vector<bool> child(model.nodes.size(), false);
        for (const tinygltf::Node& node : model.nodes)
            for (int c : node.children)
                if (c >= 0 && size_t(c) < child.size()) child[size_t(c)] = true;
        for (size_t i = 0; i < model.nodes.size(); ++i)
            if (!child[i]) roots.push_back(int(i));
    }
    for (int node : roots)
        if (Status added = reader.AddTree(node); !added) return added.GetError();
    if (reader.mMesh.mTriangles.empty()) return MakeError(ErrorCode::ParseError, inPath + ": no triangles");
    return std::move(reader.mMesh);
}

Result<IndexedMesh> LoadLevelMesh(const std::string& inPath, const LevelLoadLimits& inLimits)
{
    const std::string extension = LowerCaseExtension(inPath);
    if (extension == ".gltf" || extension == ".glb") return LoadGltfMesh(inPath, inLimits);
    if (extension == ".obj") return LoadObjMesh(inPath, inLimits);
    return MakeError(ErrorCode::InvalidArgument,
                     inPath + ": unknown level format (expected .obj, .gltf or .glb)");
}

} // namespace cairn::navmesh
