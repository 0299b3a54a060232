#!/usr/bin/env python3
"""Writes data/levels/courtyard.gltf: the sample level of the README's bake example.

A 48 m x 48 m courtyard (4 x 4 tiles of 12.8 m, plus a border) in the four materials that
data/levels/courtyard-areas.json maps to navmesh areas: grass everywhere, a road across it, a shallow
pond, stone buildings; a ramp up to a raised terrace, and a footbridge over the pond. Every object is a
glTF node with its own mesh, so the baker makes a body per object and area. The buffer is embedded (a
base64 data URI): the level is one file.

Run from the repository root: python3 tools/data/make-courtyard.py
"""
import base64
import json
import math
import struct

OUTPUT = "data/levels/courtyard.gltf"

MATERIALS = ["grass", "road", "shallow_water", "stone"]


def box(half):
    """The 8 corners and 12 outward triangles of a box centred on the origin."""
    hx, hy, hz = half
    corners = [(x, y, z) for x in (-hx, hx) for y in (-hy, hy) for z in (-hz, hz)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    triangles = []
    for a, b, c, d in faces:
        triangles += [(a, b, c), (a, c, d)]
    return corners, triangles


def quad(half_x, half_z):
    """A flat rectangle at y = 0, facing up."""
    corners = [(-half_x, 0.0, -half_z), (-half_x, 0.0, half_z), (half_x, 0.0, half_z), (half_x, 0.0, -half_z)]
    return corners, [(0, 1, 2), (0, 2, 3)]


def ramp(length, width, height):
    """A wedge rising along +x from 0 to height over length (its top is the walkable slope)."""
    hw = width / 2
    corners = [(0, 0, -hw), (0, 0, hw), (length, 0, -hw), (length, 0, hw), (length, height, -hw),
               (length, height, hw)]
    triangles = [(0, 1, 5), (0, 5, 4), (0, 2, 3), (0, 3, 1), (2, 4, 5), (2, 5, 3), (0, 4, 2), (1, 3, 5)]
    return corners, triangles


# name, (vertices, triangles), material, translation
OBJECTS = [
    ("ground", quad(24.0, 24.0), "grass", (0.0, 0.0, 0.0)),
    ("road", quad(24.0, 2.0), "road", (0.0, 0.02, 0.0)),
    ("pond", quad(5.0, 4.0), "shallow_water", (-12.0, 0.03, 12.0)),
    ("hall", box((5.0, 4.0, 3.5)), "stone", (10.0, 4.0, -11.0)),
    ("tower", box((2.0, 8.0, 2.0)), "stone", (-16.0, 8.0, -14.0)),
    ("wall_north", box((14.0, 1.5, 0.3)), "stone", (-4.0, 1.5, -20.0)),
    ("wall_east", box((0.3, 1.5, 8.0)), "stone", (20.0, 1.5, 10.0)),
    ("terrace", box((4.0, 1.0, 4.0)), "stone", (12.0, 1.0, 12.0)),
    ("terrace_ramp", ramp(6.0, 3.0, 2.0), "road", (2.0, 0.0, 12.0)),
    ("footbridge", box((0.8, 0.1, 5.5)), "road", (-12.0, 0.4, 12.0)),
]
# The ramp climbs 2 m over 6 m (18 degrees), under the default agent's 45; it meets the terrace's west side


def main():
    blob = bytearray()
    accessors, buffer_views, meshes, nodes = [], [], [], []
    for name, (vertices, triangles), material, translation in OBJECTS:
        positions = struct.pack("<%df" % (3 * len(vertices)), *[c for v in vertices for c in v])
        indices = struct.pack("<%dH" % (3 * len(triangles)), *[i for t in triangles for i in t])
        for data, target in ((positions, 34962), (indices, 34963)):
            while len(blob) % 4:
                blob.append(0)
            buffer_views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
            blob += data
        lows = [min(v[i] for v in vertices) for i in range(3)]
        highs = [max(v[i] for v in vertices) for i in range(3)]
        accessors.append({"bufferView": len(buffer_views) - 2, "componentType": 5126, "count": len(vertices),
                          "type": "VEC3", "min": lows, "max": highs})
        accessors.append({"bufferView": len(buffer_views) - 1, "componentType": 5123,
                          "count": 3 * len(triangles), "type": "SCALAR"})
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                                     "indices": len(accessors) - 1,
                                                     "material": MATERIALS.index(material)}]})
        nodes.append({"name": name, "mesh": len(meshes) - 1, "translation": list(translation)})
    gltf = {
        "asset": {"version": "2.0", "generator": "tools/data/make-courtyard.py"},
        "scene": 0,
        "scenes": [{"name": "courtyard", "nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": [{"name": m} for m in MATERIALS],
        "accessors": accessors,
        "bufferViews": buffer_views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
    }
    with open(OUTPUT, "w") as out:
        json.dump(gltf, out, indent=1)
        out.write("\n")
    print("%s: %d objects, %d bytes of geometry" % (OUTPUT, len(nodes), len(blob)))


if __name__ == "__main__":
    main()
