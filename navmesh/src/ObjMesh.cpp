#include "cairn/navmesh/ObjMesh.h"

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
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
/// What a first pass over the lines finds: tinyobjloader reads a coordinate it cannot parse ("nan", "1.2.3",
/// "x") as 0 without a word (a malformed level would load as a different level), so the vertex lines are
/// checked here, each coordinate in full; and it names a material only when a material library defines it,
/// so the names are gathered here too (the library itself, colours and textures, means nothing to a navmesh).
struct ObjScan
{
    std::vector<std::string> mMaterialNames; ///< Of every `usemtl`, in order of first use
    bool mMaterialBeforeLibrary = false;     ///< A `usemtl` before any `mtllib`
};

bool StartsWithKeyword(const std::string& inLine, const char* inKeyword)
{
    const size_t length = std::strlen(inKeyword);
    return inLine.compare(0, length, inKeyword) == 0 && inLine.size() > length &&
           (inLine[length] == ' ' || inLine[length] == '\t');
}

Result<ObjScan> ScanLines(const std::string& inPath)
{
    ObjScan scan;
    std::set<std::string> seen;
    bool library = false;
    std::ifstream file(inPath);
    std::string line;
    for (int number = 1; std::getline(file, line); ++number)
    {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        // tinyobjloader skips leading blanks: so must we, or an indented line would escape the checks
        line.erase(0, line.find_first_not_of(" \t"));
        if (StartsWithKeyword(line, "mtllib")) library = true;
        if (StartsWithKeyword(line, "usemtl"))
        {
            std::istringstream tokens(line.substr(7));
            std::string name;
            tokens >> name;
            if (!name.empty() && seen.insert(name).second) scan.mMaterialNames.push_back(name);
            scan.mMaterialBeforeLibrary = scan.mMaterialBeforeLibrary || !library;
        }
        if (!StartsWithKeyword(line, "v")) continue;
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
    return scan;
}

/// Answers every `mtllib` with one material per name the scan found, whatever the library holds (or whether
/// it exists), so that each face's material id names its `usemtl`.
class UsedMaterialsReader : public tinyobj::MaterialReader
{
public:
    explicit UsedMaterialsReader(const std::vector<std::string>& inNames) : mNames(inNames) {}

    bool operator()(const std::string&, std::vector<tinyobj::material_t>* ioMaterials,
                    std::map<std::string, int>* ioMap, std::string*, std::string*) override
    {
        for (const std::string& name : mNames)
            if (ioMap->find(name) == ioMap->end())
            {
                (*ioMap)[name] = int(ioMaterials->size());
                // Value-initialised: material_t is a plain aggregate, and a default-initialised one has
                // indeterminate bools and enums that the copy below would read (UBSan)
                tinyobj::material_t material{};
                material.name = name;
                ioMaterials->push_back(material);
            }
        return true;
    }

private:
    const std::vector<std::string>& mNames;
};

/// tinyobjloader's message with its line numbers lowered by inShift (the lines we put before the file's).
std::string ShiftLineNumbers(const std::string& inMessage, int inShift)
{
    if (inShift == 0) return inMessage;
    static const std::regex number(R"(line:? (\d+))");
    std::string shifted;
    auto last = inMessage.cbegin();
    for (std::sregex_iterator it(inMessage.begin(), inMessage.end(), number), end; it != end; ++it)
    {
        shifted.append(last, (*it)[1].first);
        shifted += std::to_string(std::stoll((*it)[1].str()) - inShift);
        last = (*it)[1].second;
    }
    shifted.append(last, inMessage.cend());
    return shifted;
}
} // namespace

Result<IndexedMesh> LoadObjMesh(const std::string& inPath)
{
    std::error_code error;
    if (!std::filesystem::is_regular_file(inPath, error))
        return MakeError(ErrorCode::IOError, inPath + ": not a readable file");
    Result<ObjScan> scan = ScanLines(inPath);
    if (!scan) return scan.GetError();
    std::ifstream file(inPath, std::ios::binary);
    std::stringstream text;
    // Materials used before any library would have no name: a library line of our own goes first then
    const int linesBefore = scan.Value().mMaterialBeforeLibrary ? 1 : 0;
    if (linesBefore != 0) text << "mtllib cairn-used-materials\n";
    text << file.rdbuf();
    tinyobj::attrib_t attributes;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warnings, errors;
    UsedMaterialsReader materialReader(scan.Value().mMaterialNames);
    if (!tinyobj::LoadObj(&attributes, &shapes, &materials, &warnings, &errors, &text, &materialReader, true,
                          false))
        return MakeError(ErrorCode::ParseError, inPath + ": " + ShiftLineNumbers(errors, linesBefore));

    IndexedMesh mesh;
    const std::vector<tinyobj::real_t>& positions = attributes.vertices;
    mesh.mVertices.reserve(positions.size() / 3);
    for (size_t i = 0; i + 2 < positions.size(); i += 3)
    {
        const Vec3 v(positions[i], positions[i + 1], positions[i + 2]);
        if (!IsValidWorldPosition(v))
            return MakeError(ErrorCode::ParseError, inPath + ": vertex " + std::to_string(i / 3 + 1) +
                                                        " is not finite or beyond the world's range");
        mesh.mVertices.push_back(v);
    }
    for (const tinyobj::material_t& material : materials)
        mesh.mMaterials.push_back(material.name);
    for (const tinyobj::shape_t& shape : shapes)
    {
        MeshObject object{shape.name, uint32_t(mesh.mTriangles.size()), 0};
        size_t offset = 0;
        for (size_t face = 0; face < shape.mesh.num_face_vertices.size(); ++face)
        {
            if (shape.mesh.num_face_vertices[face] != 3 || offset + 3 > shape.mesh.indices.size())
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
            const int material = face < shape.mesh.material_ids.size() ? shape.mesh.material_ids[face] : -1;
            mesh.mTriangleMaterials.push_back(material >= 0 && size_t(material) < mesh.mMaterials.size()
                                                  ? uint32_t(material)
                                                  : IndexedMesh::cNoMaterial);
            offset += 3;
        }
        object.mNumTriangles = uint32_t(mesh.mTriangles.size()) - object.mFirstTriangle;
        if (object.mNumTriangles > 0) mesh.mObjects.push_back(std::move(object));
    }
    if (mesh.mTriangles.empty()) return MakeError(ErrorCode::ParseError, inPath + ": no triangles");
    return mesh;
}

} // namespace cairn::navmesh
