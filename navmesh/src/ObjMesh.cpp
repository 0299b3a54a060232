#include "cairn/navmesh/ObjMesh.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tiny_obj_loader.h>

namespace cairn::navmesh
{

AABB IndexedMesh::GetBounds() const
{
    AABB bounds;
    for (const Vec3& v : mVertices)
        bounds.Encapsulate(v);
    return bounds;
}

TileGeometry IndexedMesh::ToTileGeometry(uint8_t inArea) const
{
    TileGeometry geometry;
    geometry.mVertices.reserve(mVertices.size() * 3);
    for (const Vec3& v : mVertices)
        geometry.mVertices.insert(geometry.mVertices.end(), {v.x(), v.y(), v.z()});
    geometry.mTriangles.reserve(mTriangles.size() * 3);
    for (const std::array<uint32_t, 3>& t : mTriangles)
        geometry.mTriangles.insert(geometry.mTriangles.end(), {int(t[0]), int(t[1]), int(t[2])});
    geometry.mAreas.assign(mTriangles.size(), inArea);
    return geometry;
}

namespace
{
/// tinyobjloader reads a coordinate it cannot parse ("nan", "1.2.3", "x") as 0 without a word: a malformed
/// level would load as a different level. So the vertex lines are checked first, each coordinate in full.
Status CheckVertexLines(const std::string& inPath)
{
    std::ifstream file(inPath);
    std::string line;
    for (int number = 1; std::getline(file, line); ++number)
    {
        if (line.size() < 2 || line[0] != 'v' || (line[1] != ' ' && line[1] != '\t')) continue;
        std::istringstream tokens(line.substr(2));
        std::string token;
        int coordinates = 0;
        while (tokens >> token)
        {
            float value = 0.0f;
            const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
            if (error != std::errc() || end != token.data() + token.size() || !std::isfinite(value))
                return MakeError(ErrorCode::ParseError, inPath + ":" + std::to_string(number) + ": '" +
                                                            token + "' is not a finite number");
            ++coordinates;
        }
        if (coordinates < 3)
            return MakeError(ErrorCode::ParseError,
                             inPath + ":" + std::to_string(number) + ": a vertex needs x, y and z");
    }
    return Status::Ok();
}
} // namespace

Result<IndexedMesh> LoadObjMesh(const std::string& inPath)
{
    std::error_code error;
    if (!std::filesystem::is_regular_file(inPath, error))
        return MakeError(ErrorCode::IOError, inPath + ": not a readable file");
    if (Status checked = CheckVertexLines(inPath); !checked) return checked.GetError();
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    config.mtl_search_path = ""; // Materials are not used: do not go looking for .mtl files
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(inPath, config))
        return MakeError(ErrorCode::ParseError, inPath + ": " + reader.Error());

    IndexedMesh mesh;
    const std::vector<tinyobj::real_t>& positions = reader.GetAttrib().vertices;
    mesh.mVertices.reserve(positions.size() / 3);
    for (size_t i = 0; i + 2 < positions.size(); i += 3)
    {
        const Vec3 v(positions[i], positions[i + 1], positions[i + 2]);
        if (!IsValidWorldPosition(v))
            return MakeError(ErrorCode::ParseError, inPath + ": vertex " + std::to_string(i / 3 + 1) +
                                                        " is not finite or beyond the world's range");
        mesh.mVertices.push_back(v);
    }
    for (const tinyobj::shape_t& shape : reader.GetShapes())
    {
        size_t offset = 0;
        for (unsigned char faceSize : shape.mesh.num_face_vertices)
        {
            if (faceSize != 3 || offset + 3 > shape.mesh.indices.size())
                return MakeError(ErrorCode::ParseError,
                                 inPath + ": a face could not be split into triangles");
            std::array<uint32_t, 3> triangle;
            for (int k = 0; k < 3; ++k)
            {
                const int index = shape.mesh.indices[offset + size_t(k)].vertex_index;
                if (index < 0 || size_t(index) >= mesh.mVertices.size())
                    return MakeError(ErrorCode::ParseError, inPath + ": a face names vertex " +
                                                                std::to_string(index + 1) + " of " +
                                                                std::to_string(mesh.mVertices.size()));
                triangle[size_t(k)] = uint32_t(index);
            }
            mesh.mTriangles.push_back(triangle);
            offset += 3;
        }
    }
    if (mesh.mTriangles.empty()) return MakeError(ErrorCode::ParseError, inPath + ": no triangles");
    return mesh;
}

} // namespace cairn::navmesh
