#!/usr/bin/env python3
"""Writes scenes/cholecystectomy.json: examples/cholecystectomy.cpp as a scene file.

The gallbladder's bounds place the membrane, its pins and the tools; this
computes them from the same mesh (data/meshes/tet/gallbladder_volumetric.vtk,
big-endian float32 points: Python's floats are the same doubles the reader
makes of them) and writes them out: the membrane inline, its liver-bed pins,
its near edge's two-way attachments to the gallbladder, the grasper's lift,
a cautery at each frame of 0.8 to 1.2 s and the blade's strokes at each
frame of 1.5 to 1.83 s (the example's own numbers). What the example reads
from the running scene (where the membrane's middle hangs when the grasper
closes, where the strand is while it burns, where the blade's line is) the
script's landmarks find.

    scenes/generators/cholecystectomy.py DATA_DIR > scenes/cholecystectomy.json

DATA_DIR: the data folder (data/ or a build's data folder).
"""
import math
import os
import struct
import sys

import scene_json

FRAME, CELL = 1.0 / 60.0, 1e-3
NX, NZ = 40, 20


def section(data, name, fmt):
    """A legacy binary VTK section's header numbers and its big-endian values."""
    at = data.index(name + b" ")
    end = data.index(b"\n", at)
    header = data[at:end].split()[1:]
    count = int(header[1]) if name == b"CELLS" else 3 * int(header[0]) if name == b"POINTS" else int(header[0])
    return header, struct.unpack(">%d%s" % (count, fmt), data[end + 1:end + 1 + 4 * count])


def read_vtk_points(path):
    """The points of a legacy binary VTK file that its tets use, as doubles,
    in the reader's order: the others dropped, the rest numbered in the
    order the tets first use them (drop_unused_vertices)."""
    with open(path, "rb") as f:
        data = f.read()
    header, values = section(data, b"POINTS", "f")
    assert header[1] == b"float", header
    _, cells = section(data, b"CELLS", "i")
    _, types = section(data, b"CELL_TYPES", "i")
    used, order, at = set(), [], 0
    for kind in types:
        if kind == 10:  # VTK_TETRA
            for i in cells[at + 1:at + 5]:
                if i not in used:
                    used.add(i)
                    order.append(i)
        at += 1 + cells[at]
    return [list(values[3 * i:3 * i + 3]) for i in order]


data = sys.argv[1] if len(sys.argv) > 1 else "data"
organ = [[c * 1e-3 for c in v] for v in read_vtk_points(os.path.join(data, "meshes/tet/gallbladder_volumetric.vtk"))]
lo = [min(v[k] for v in organ) for k in range(3)]
hi = [max(v[k] for v in organ) for k in range(3)]
centre = [0.5 * (lo[0] + hi[0]), lo[1], 0.5 * (lo[2] + hi[2])]
near_z, far_z = centre[2], centre[2] - 0.02

vertices = [[centre[0] - 0.02 + i * CELL, centre[1] - CELL, far_z + k * CELL]
            for i in range(NX + 1) for k in range(NZ + 1)]
triangles = []
for i in range(NX):
    for k in range(NZ):
        a = i * (NZ + 1) + k
        b, c = a + 1, a + NZ + 1
        triangles += [[a, b, c + 1], [a, c + 1, c]]
liver_bed = [v for v, p in enumerate(vertices) if p[2] < far_z + 1e-9]
edge = [v for v, p in enumerate(vertices) if p[2] >= near_z - 1e-9]
# The organ's pins: y > hi - 0.2 (hi - lo) in the example; a box's bounds are included.
pin_above = hi[1] - 0.2 * (hi[1] - lo[1])
pin_bottom = math.nextafter(pin_above, math.inf)
assert sum(v[1] > pin_above for v in organ) == sum(v[1] >= pin_bottom for v in organ)

# The near edge's attachments: each vertex to its three nearest gallbladder
# vertices (the first of equals), at their distances (summed as the example
# sums them).
attached = []
for v in edge:
    p = vertices[v]
    by_distance = []
    for u, q in enumerate(organ):
        d2 = 0.0
        for k in range(3):
            d2 += (q[k] - p[k]) * (q[k] - p[k])
        by_distance.append((d2, u))
    for d2, u in sorted(by_distance)[:3]:
        attached.append({"a": {"body_kind": "tri", "body": 0, "vertices": [v], "weights": [1.0]},
                         "b": {"body_kind": "tet", "body": 0, "vertices": [u], "weights": [1.0]},
                         "compliance": 0.0, "rest_length": math.sqrt(d2)})

# The grasper closes at frame 30 on the membrane's middle where it hangs
# then: the mean of the vertices within 1.5 mm of it at rest (a landmark).
near_middle = [v for v, p in enumerate(vertices)
               if abs(p[0] - centre[0]) <= 1.5e-3 and abs(p[2] - (near_z - 0.01)) <= 1.5e-3]
strand = [v for v, p in enumerate(vertices)
          if abs(p[0] - (centre[0] + 0.012)) < 0.5 * CELL and abs(p[2] - (far_z + 4e-3)) < 0.5 * CELL][-1]

actions = [{"frame": 30, "do": "close_grasper", "grasper": 0,
            "at": {"body_kind": "tri", "body": 0, "vertices": near_middle},
            "half_extents": [1.5e-3, 2e-3, 1.5e-3]}]
for frame in range(1, 151):
    t = frame * FRAME
    if 0.8 <= t < 1.2:  # where the strand is now
        actions.append({"frame": frame, "do": "cauterize", "body_kind": "tri", "body": 0,
                        "at": {"body_kind": "tri", "body": 0, "vertices": [strand]},
                        "radius": 3e-3, "seconds": FRAME, "dwell_time": 0.1})
    if 90 <= frame <= 110:  # on the vertex 2 mm from the edge at rest, where it is now
        on_line = 2 * (frame - 90) * (NZ + 1) + (NZ - 2)
        actions.append({"frame": frame, "do": "cut", "body_kind": "tri", "body": 0,
                        "at": {"body_kind": "tri", "body": 0, "vertices": [on_line]},
                        "from": {"a": [-3e-3, 6e-3, 0.0], "b": [-3e-3, -9e-3, 0.0]},
                        "to": {"a": [1e-3, 6e-3, 0.0], "b": [1e-3, -9e-3, 0.0]}})

scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "A cholecystectomy-like sequence: a grasper lifts the membrane joining the gallbladder to the "
                   "liver bed, a cautery tip burns a strand, a blade cuts the membrane free "
                   "(examples/cholecystectomy.cpp; written by scenes/generators/cholecystectomy.py). The "
                   "membrane's near edge is attached two ways to the gallbladder; the grasper closes where the "
                   "membrane's middle hangs at 0.5 s, the cautery burns where the strand is and the blade's strokes "
                   "follow the membrane (landmarks); the grasper's lift is relative to where it closed.",
    "run": {"frames": 150, "every": 5},
    "solver": {"time_step": FRAME, "substeps": 10, "iterations": 2},
    "topology_changes": True,
    "tet_bodies": [{
        "name": "gallbladder",
        "mesh": {"file": "data:meshes/tet/gallbladder_volumetric.vtk", "scale": 1e-3},
        "density": 1050.0,
        "material": "corotational", "youngs_modulus": 2e4, "poisson_ratio": 0.45,
        "velocity_damping": 2.0,
        "pinned": [{"min": [-1e3, pin_bottom, -1e3], "max": [1e3, 1e3, 1e3]}],
    }],
    "tri_bodies": [{
        "name": "membrane",
        "mesh": {"vertices": vertices, "triangles": triangles},
        "density": 1050.0,
        "thickness": 1e-3,
        "distance_compliance": 1.0 / 5e4,
        "area_compliance": 1.0 / 5e4,
        "velocity_damping": 2.0,
        "pinned": liver_bed,
    }],
    "body_attachments": attached,
    "graspers": [{"capacity": 64, "compliance": 0.0}],
    "script": {
        "poses": [{"grasper": 0, "relative": True,
                   "keys": [{"frame": 30, "position": [0.0, 0.0, 0.0]}, {"frame": 90, "position": [0.0, 0.015, 0.0]}]}],
        "actions": actions,
    },
}
scene_json.write(scene, sys.stdout)
