#!/usr/bin/env python3
"""Writes scenes/cholecystectomy.json: examples/cholecystectomy.cpp as a scene file.

The gallbladder's bounds place the membrane, its pins and the tools; this
computes them from the same mesh (data/meshes/tet/gallbladder_volumetric.vtk,
big-endian float32 points: Python's floats are the same doubles the reader
makes of them) and writes them out: the membrane inline, its liver-bed pins,
its near edge's attachments, the grasper's path, a cautery at each frame of
0.8 to 1.2 s and the blade's strokes at each frame of 1.5 to 2.3 s (the
example's own numbers). What the example reads from the running scene a
script cannot: the description says what stands in for it.

    scenes/generators/cholecystectomy.py DATA_DIR > scenes/cholecystectomy.json
    sinew run scenes/cholecystectomy.json --backend cpu --frames 29 --quiet --positions hang.f32
    scenes/generators/cholecystectomy.py DATA_DIR hang.f32 > scenes/cholecystectomy.json

DATA_DIR: the data folder (data/ or a build's data folder). The grasper
closes at frame 30 on the membrane's middle where it hangs then: the first
pass closes it at rest (on nothing, the membrane has sagged), the second
where the first pass's membrane hangs after 29 frames (HANG, the runner's
positions, float32 xyzw per particle, the gallbladder's first).
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
    """The points of a legacy binary VTK file that its tets use (the reader
    drops the others), as doubles."""
    with open(path, "rb") as f:
        data = f.read()
    header, values = section(data, b"POINTS", "f")
    assert header[1] == b"float", header
    _, cells = section(data, b"CELLS", "i")
    _, types = section(data, b"CELL_TYPES", "i")
    used, at = set(), 0
    for kind in types:
        if kind == 10:  # VTK_TETRA
            used.update(cells[at + 1:at + 5])
        at += 1 + cells[at]
    return [list(values[3 * i:3 * i + 3]) for i in sorted(used)]


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

# The grasper closes at frame 30 on the membrane's middle: the mean of the
# vertices within 1.5 mm of it at rest, where they hang after 29 frames.
near_middle = [v for v, p in enumerate(vertices)
               if abs(p[0] - centre[0]) <= 1.5e-3 and abs(p[2] - (near_z - 0.01)) <= 1.5e-3]
hang = vertices
if len(sys.argv) > 2:
    with open(sys.argv[2], "rb") as f:
        xyzw = f.read()
    first = len(organ)  # the membrane's particles follow the gallbladder's
    assert len(xyzw) == 16 * (first + len(vertices)), "not this scene's positions"
    hang = [list(struct.unpack_from("<3f", xyzw, 16 * (first + v))) for v in range(len(vertices))]
middle = [sum(hang[v][k] for v in near_middle) / len(near_middle) for k in range(3)]
lifted = [middle[0], middle[1] + 0.015, middle[2]]
strand = [p for p in vertices
          if abs(p[0] - (centre[0] + 0.012)) < 0.5 * CELL and abs(p[2] - (far_z + 4e-3)) < 0.5 * CELL][-1]

actions = [{"frame": 30, "do": "close_grasper", "grasper": 0, "position": middle,
            "half_extents": [1.5e-3, 2e-3, 1.5e-3]}]
for frame in range(1, 151):
    t = frame * FRAME
    if 0.8 <= t < 1.2:  # the example burns where the strand is now; this where it was at rest
        actions.append({"frame": frame, "do": "cauterize", "body_kind": "tri", "body": 0, "centre": strand,
                        "radius": 3e-3, "seconds": FRAME, "dwell_time": 0.1})
    if 1.5 <= t < 2.3:
        bx, bz = centre[0] - 0.021 + 2e-3 * (frame - 90), near_z - 2e-3
        actions.append({"frame": frame, "do": "cut", "body_kind": "tri", "body": 0,
                        "from": {"a": [bx - 2e-3, centre[1] + 5e-3, bz], "b": [bx - 2e-3, centre[1] - 1e-2, bz]},
                        "to": {"a": [bx + 2e-3, centre[1] + 5e-3, bz], "b": [bx + 2e-3, centre[1] - 1e-2, bz]}})

scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "A cholecystectomy-like sequence: a grasper lifts the membrane joining the gallbladder to the "
                   "liver bed, a cautery tip burns a strand, a blade cuts the membrane free "
                   "(examples/cholecystectomy.cpp; written by scenes/generators/cholecystectomy.py). Differences "
                   "from the example, which reads the running scene: its membrane's near edge follows the "
                   "gallbladder's vertices every frame (targets moved to them), here that edge is attached to "
                   "targets fixed where it lies at rest; its grasper closes where the membrane's middle hangs at "
                   "0.5 s, here where it hung at 0.5 s in a run of this scene (written in as numbers); its cautery burns where the strand is now, here where it "
                   "was at rest. The bodies, materials, solver settings, the grasper's lift and the blade's "
                   "strokes are the example's.",
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
    "targets": [vertices[v] for v in edge],
    "attachments": [{"vertex": {"body_kind": "tri", "body": 0, "vertex": v}, "target": i, "compliance": 0.0}
                    for i, v in enumerate(edge)],
    "graspers": [{"capacity": 64, "compliance": 0.0}],
    "script": {
        "poses": [{"grasper": 0, "keys": [{"frame": 30, "position": middle}, {"frame": 90, "position": lifted}]}],
        "actions": actions,
    },
}
scene_json.write(scene, sys.stdout)
