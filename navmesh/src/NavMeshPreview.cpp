#include "cairn/navmesh/NavMeshPreview.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>
#include <vector>

namespace cairn::navmesh
{

namespace
{

/// Calls inVisit(tile) for every tile with data.
template <class Visit> void ForEachTile(const dtNavMesh& inNavMesh, Visit&& inVisit)
{
    for (int i = 0; i < inNavMesh.getMaxTiles(); ++i)
    {
        const dtMeshTile* tile = inNavMesh.getTile(i);
        if (tile != nullptr && tile->header != nullptr && tile->dataSize > 0) inVisit(*tile);
    }
}

/// A colour per area id that neighbouring ids do not share (golden-angle hues); Recast's walkable area, the
/// default ground, is a plain green.
std::string AreaColour(int inArea)
{
    if (inArea == 63) return "#7cc576"; // RC_WALKABLE_AREA
    const float hue = std::fmod(float(inArea) * 137.508f, 360.0f);
    char colour[32];
    std::snprintf(colour, sizeof(colour), "hsl(%.0f,65%%,60%%)", hue);
    return colour;
}

/// Recast's walkable area is Cairn's default ground (area 0); the others keep their id.
std::string AreaName(int inArea)
{
    return inArea == 63 ? std::string("ground") : "area " + std::to_string(inArea);
}

} // namespace

std::string NavMeshToObj(const dtNavMesh& inNavMesh)
{
    std::string obj = "# Cairn navmesh: detail triangles of every polygon\n";
    char line[96];
    int firstVertex = 1;
    ForEachTile(
        inNavMesh,
        [&](const dtMeshTile& inTile)
        {
            std::snprintf(line, sizeof(line), "o tile_%d_%d\n", inTile.header->x, inTile.header->y);
            obj += line;
            for (int p = 0; p < inTile.header->polyCount; ++p)
            {
                const dtPoly& poly = inTile.polys[p];
                if (poly.getType() == DT_POLYTYPE_OFFMESH_CONNECTION) continue;
                const dtPolyDetail& detail = inTile.detailMeshes[p];
                for (int t = 0; t < detail.triCount; ++t)
                {
                    const unsigned char* triangle = &inTile.detailTris[(detail.triBase + unsigned(t)) * 4];
                    for (int k = 0; k < 3; ++k)
                    {
                        // The first vertCount indices are the polygon's own vertices, then detail ones
                        const float* v =
                            triangle[k] < poly.vertCount
                                ? &inTile.verts[poly.verts[triangle[k]] * 3]
                                : &inTile.detailVerts[(detail.vertBase + (triangle[k] - poly.vertCount)) * 3];
                        std::snprintf(line, sizeof(line), "v %.3f %.3f %.3f\n", v[0], v[1], v[2]);
                        obj += line;
                    }
                    std::snprintf(line, sizeof(line), "f %d %d %d\n", firstVertex, firstVertex + 1,
                                  firstVertex + 2);
                    obj += line;
                    firstVertex += 3;
                }
            }
        });
    return obj;
}

std::string NavMeshToSvg(const dtNavMesh& inNavMesh, const SvgPreviewSettings& inSettings)
{
    // The extent of every tile's bounds, x and z
    float minX = 1e30f, minZ = 1e30f, maxX = -1e30f, maxZ = -1e30f;
    ForEachTile(inNavMesh,
                [&](const dtMeshTile& inTile)
                {
                    minX = std::min(minX, inTile.header->bmin[0]);
                    minZ = std::min(minZ, inTile.header->bmin[2]);
                    maxX = std::max(maxX, inTile.header->bmax[0]);
                    maxZ = std::max(maxZ, inTile.header->bmax[2]);
                });
    const float margin = 10.0f, legendHeight = 24.0f;
    if (minX > maxX)
        return "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"40\"><text x=\"10\" "
               "y=\"25\" "
               "font-family=\"sans-serif\" font-size=\"14\">empty navmesh</text></svg>\n";
    const float scale =
        std::max(inSettings.mMaxPixels - 2.0f * margin, 16.0f) / std::max({maxX - minX, maxZ - minZ, 1e-3f});
    const float width = (maxX - minX) * scale + 2.0f * margin;
    const float height = (maxZ - minZ) * scale + 2.0f * margin + legendHeight;
    auto px = [&](float inX) { return margin + (inX - minX) * scale; };
    auto pz = [&](float inZ) { return margin + legendHeight + (inZ - minZ) * scale; };

    std::string svg;
    char text[256];
    std::snprintf(text, sizeof(text),
                  "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                  "viewBox=\"0 0 %.0f %.0f\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
                  width, height, width, height);
    svg += text;
    std::map<int, int> polygonsPerArea;
    std::string links;
    std::vector<std::pair<float, std::string>> polygons; // Mean height, SVG element
    ForEachTile(
        inNavMesh,
        [&](const dtMeshTile& inTile)
        {
            if (inSettings.mTileBorders)
            {
                std::snprintf(text, sizeof(text),
                              "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
                              "stroke=\"#cccccc\" stroke-width=\"0.5\"/>\n",
                              px(inTile.header->bmin[0]), pz(inTile.header->bmin[2]),
                              (inTile.header->bmax[0] - inTile.header->bmin[0]) * scale,
                              (inTile.header->bmax[2] - inTile.header->bmin[2]) * scale);
                svg += text;
            }
            for (int p = 0; p < inTile.header->polyCount; ++p)
            {
                const dtPoly& poly = inTile.polys[p];
                if (poly.getType() == DT_POLYTYPE_OFFMESH_CONNECTION)
                {
                    const float* a = &inTile.verts[poly.verts[0] * 3];
                    const float* b = &inTile.verts[poly.verts[1] * 3];
                    std::snprintf(text, sizeof(text),
                                  "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#d03030\" "
                                  "stroke-width=\"1.5\" marker-end=\"url(#arrow)\"/>\n",
                                  px(a[0]), pz(a[2]), px(b[0]), pz(b[2]));
                    links += text;
                    continue;
                }
                ++polygonsPerArea[poly.getArea()];
                std::string shape = "<polygon points=\"";
                float height = 0.0f;
                for (int v = 0; v < poly.vertCount; ++v)
                {
                    const float* vertex = &inTile.verts[poly.verts[v] * 3];
                    std::snprintf(text, sizeof(text), "%s%.1f,%.1f", v == 0 ? "" : " ", px(vertex[0]),
                                  pz(vertex[2]));
                    shape += text;
                    height += vertex[1] / float(poly.vertCount);
                }
                shape += "\" fill=\"" + AreaColour(poly.getArea()) +
                         "\" stroke=\"#2f4f2f\" stroke-width=\"0.4\"/>\n";
                polygons.emplace_back(height, std::move(shape));
            }
        });
    // Lower floors first, so that a level above covers them as it does seen from above
    std::stable_sort(polygons.begin(), polygons.end(),
                     [](const auto& inL, const auto& inR) { return inL.first < inR.first; });
    for (const auto& [height, shape] : polygons)
        svg += shape;
    if (!links.empty())
        svg += "<defs><marker id=\"arrow\" viewBox=\"0 0 10 10\" refX=\"10\" refY=\"5\" markerWidth=\"6\" "
               "markerHeight=\"6\" orient=\"auto\"><path d=\"M0,0 L10,5 L0,10 z\" fill=\"#d03030\"/></marker>"
               "</defs>\n" +
               links;
    // Legend: one swatch per area id with its polygon count
    float x = margin;
    for (const auto& [area, count] : polygonsPerArea)
    {
        std::snprintf(text, sizeof(text),
                      "<rect x=\"%.0f\" y=\"%.0f\" width=\"12\" height=\"12\" fill=\"%s\"/><text x=\"%.0f\" "
                      "y=\"%.0f\" font-family=\"sans-serif\" font-size=\"12\">%s: %d polygons</text>\n",
                      x, margin - 2.0f, AreaColour(area).c_str(), x + 16.0f, margin + 8.0f,
                      AreaName(area).c_str(), count);
        svg += text;
        x += 150.0f;
    }
    svg += "</svg>\n";
    return svg;
}

} // namespace cairn::navmesh
