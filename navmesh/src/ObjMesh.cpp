#include "LevelFileAccess.h"
#include "cairn/navmesh/LevelMesh.h"

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
using namespace cairn::physics;

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

/// Empty when inToken is a face corner tinyobjloader reads as written: a non-zero vertex index (negative
/// counts back from the last vertex) that fits an int, then optionally /texcoord and /normal indices, which
/// may be empty. Else what is wrong: tinyobjloader wraps an index that overflows into some other vertex.
std::string CheckFaceCorner(const std::string& inToken, int& outVertex)
{
    size_t start = 0;
    for (int part = 0; part < 3 && start <= inToken.size(); ++part)
    {
        const size_t slash = std::min(inToken.find('/', start), inToken.size());
        const char* first = inToken.data() + start;
        const char* last = inToken.data() + slash;
        if (first != last || part == 0)
        {
            int index = 0;
            const auto [end, error] = std::from_chars(first, last, index);
            if (error != std::errc() || end != last || index == 0)
                return "'" + inToken +
                       "' is not a face corner (vertex/texcoord/normal, whole non-zero numbers)";
            if (part == 0) outVertex = index;
        }
        start = slash + 1;
    }
    if (start <= inToken.size()) return "'" + inToken + "' has more than three indices";
    return "";
}

/// inText with CR LF and lone CR line ends made LF: tinyobjloader ends lines at all three, and the checks
/// here must see the lines it sees (a CR-only file was one line to them, and escaped them all).
std::string NormalizeLineEnds(const std::vector<unsigned char>& inBytes)
{
    std::string text;
    text.reserve(inBytes.size());
    for (size_t i = 0; i < inBytes.size(); ++i)
    {
        const char c = char(inBytes[i]);
        if (c != '\r')
            text += c;
        else if (i + 1 >= inBytes.size() || inBytes[i + 1] != '\n')
            text += '\n';
    }
    return text;
}

Result<ObjScan> ScanLines(const std::string& inPath, const std::string& inText)
{
    ObjScan scan;
    std::set<std::string> seen;
    bool library = false;
    std::istringstream file(inText);
    std::string line;
    int vertices = 0;                       // Vertex lines so far: a negative index counts back from here
    int highestVertex = 0, highestLine = 0; // A positive index may name a vertex defined later
    for (int number = 1; std::getline(file, line); ++number)
    {
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
        if (StartsWithKeyword(line, "f"))
        {
            std::istringstream tokens(line.substr(2));
            std::string token;
            int corners = 0;
            while (tokens >> token)
            {
                int vertex = 0;
                if (const std::string problem = CheckFaceCorner(token, vertex); !problem.empty())
                    return MakeError(ErrorCode::ParseError,
                                     inPath + ":" + std::to_string(number) + ": " + problem);
                if (vertex < 0 && -int64_t(vertex) > vertices)
                    return MakeError(ErrorCode::ParseError,
                                     inPath + ":" + std::to_string(number) + ": a face names vertex " +
                                         std::to_string(vertex) + ", back past the first of " +
                                         std::to_string(vertices));
                if (vertex > highestVertex) highestVertex = vertex, highestLine = number;
                ++corners;
            }
            // tinyobjloader drops a face of fewer corners without a word
            if (corners < 3)
                return MakeError(ErrorCode::ParseError, inPath + ":" + std::to_string(number) +
                                                            ": a face needs 3 corners or more, it has " +
                                                            std::to_string(corners));
            continue;
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
        ++vertices;
    }
    if (highestVertex > vertices)
        return MakeError(ErrorCode::ParseError, inPath + ":" + std::to_string(highestLine) +
                                                    ": a face names vertex " + std::to_string(highestVertex) +
                                                    " of " + std::to_string(vertices));
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
        // Every name goes in at the first library line, once: answering each of 20,000 `mtllib` lines with
        // all 20,000 names took 28 s (tinyobjloader keeps the map between calls)
        if (mAnswered) return true;
        mAnswered = true;
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
    bool mAnswered = false;
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

Result<IndexedMesh> LoadObjMesh(const std::string& inPath, const LevelLoadLimits& inLimits)
{
    Result<std::vector<unsigned char>> bytes = ReadLevelFile(inPath, inLimits.mMaxFileBytes);
    if (!bytes) return bytes.GetError();
    const std::string normalized = NormalizeLineEnds(bytes.Value());
    Result<ObjScan> scan = ScanLines(inPath, normalized);
    if (!scan) return scan.GetError();
    std::stringstream text;
    // Materials used before any library would have no name: a library line of our own goes first then
    const int linesBefore = scan.Value().mMaterialBeforeLibrary ? 1 : 0;
    if (linesBefore != 0) text << "mtllib cairn-used-materials\n";
    text << normalized;
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
    if (positions.size() / 3 > inLimits.mMaxVertices)
        return MakeError(ErrorCode::ParseError, inPath + ": " + std::to_string(positions.size() / 3) +
                                                    " vertices, over the limit of " +
                                                    std::to_string(inLimits.mMaxVertices) +
                                                    " (LevelLoadLimits::mMaxVertices)");
    size_t triangles = 0;
    for (const tinyobj::shape_t& shape : shapes)
        triangles += shape.mesh.num_face_vertices.size();
    if (triangles > inLimits.mMaxTriangles)
        return MakeError(ErrorCode::ParseError,
                         inPath + ": " + std::to_string(triangles) + " triangles, over the limit of " +
                             std::to_string(inLimits.mMaxTriangles) + " (LevelLoadLimits::mMaxTriangles)");
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
