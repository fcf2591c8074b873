#!/usr/bin/env python3
"""Writes scenes/bleeding_kidney.json: the bleeding reference scene S4
(examples/bleeding_kidney.cpp, examples/common/bleeding_organ_scene.cpp) as a
scene file.

kidney_57k laid on its back (the file's z up: "axes": ["x", "z", "-y"]),
corotational at 20 kPa and pinned below its middle; blood from a cut vessel
over its highest vertex (3 ml/s, pulsing +-50% at 72 beats a minute) pools
on it and runs off into a drain (a sink ball under the kidney's upper
part); from 1 s a suction tip comes down onto the wound and circles it. The
blood couples to the kidney's boundary triangles with a vertex above the
drain's level less 8 mm. The bounds, the wound, the pins and the drain are
computed here from the same mesh file as the example computes them (Python's
floats are the same IEEE doubles, its math.sin and math.cos the same C
library's); the emitter and the suction tip are set at every frame, as the
example sets them.

    scenes/generators/bleeding_kidney.py DATA_DIR > scenes/bleeding_kidney.json

DATA_DIR: a build's data folder (build/data: the packed meshes unpacked).
"""
import math
import os
import sys

import scene_json
from mesh_files import read_node

FRAME = 1.0 / 60.0
SPACING, RHO, STEPS_PER_FRAME = 1e-3, 1060.0, 136
SUCTION_RADIUS, DRAIN_BALL = 4e-3, 1.0
FLOW = 3.0 * 1e-6   # [m^3/s]: the example's 3 ml/s
SUCTION_START = 1.0  # [s]
FRAMES = 120


data = sys.argv[1] if len(sys.argv) > 1 else "build/data"
mesh = [[c * 1e-3 for c in v] for v in read_node(os.path.join(data, "meshes/tet/kidney_57k.node"))]
mesh = [[v[0], v[2], -v[1]] for v in mesh]  # laid on its back
lo = [min(v[k] for v in mesh) for k in range(3)]
hi = [max(v[k] for v in mesh) for k in range(3)]
drain_level = lo[1] + 0.7 * (hi[1] - lo[1])
drain_centre = [0.5 * (lo[0] + hi[0]), drain_level - DRAIN_BALL, 0.5 * (lo[2] + hi[2])]
wound = [v for v in mesh if v[1] >= hi[1]][-1]  # the highest vertex (the last of equals)
rest = lo[1] + 0.5 * (hi[1] - lo[1])  # pinned below (strictly): a box's bounds are included
assert sum(v[1] < rest for v in mesh) == sum(v[1] <= math.nextafter(rest, -math.inf) for v in mesh)


def vessel_at(t):
    rate = FLOW * (1.0 + 0.5 * math.sin(2.0 * math.pi * 1.2 * t))
    return {"centre": [wound[0], wound[1] + 2e-3, wound[2]], "direction": [0.0, -1.0, 0.0], "radius": 2e-3,
            "flow_rate": rate}


def suction_at(t):
    parked = [wound[0], wound[1] + 0.5, wound[2]]
    if t < SUCTION_START:
        return {"centre": parked, "radius": SUCTION_RADIUS}
    down = min((t - SUCTION_START) / 0.25, 1.0)
    turn = 2.0 * math.pi * 0.5 * max(t - SUCTION_START - 0.25, 0.0)
    working = [wound[0] + 8e-3 * math.cos(turn), wound[1] + 3e-3, wound[2] + 8e-3 * math.sin(turn)]
    return {"centre": [parked[a] + down * (working[a] - parked[a]) for a in range(3)], "radius": SUCTION_RADIUS}


actions = []
for frame in range(1, FRAMES + 1):
    t = frame * FRAME
    actions.append(dict({"frame": frame, "do": "set_emitter", "emitter": 0}, **vessel_at(t)))
    actions.append(dict({"frame": frame, "do": "set_sink", "sink": 0}, **suction_at(t)))

scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "The bleeding reference scene S4: a cut vessel bleeds onto the kidney (kidney_57k), the blood "
                   "pools and runs off into a drain, and from 1 s a suction tip takes it; SPH coupled both ways "
                   "with the tissue (examples/bleeding_kidney.cpp; written by scenes/generators/bleeding_kidney.py).",
    "run": {"frames": FRAMES, "every": 10},
    "solver": {"time_step": FRAME, "substeps": 10, "iterations": 1},
    "tet_bodies": [{
        "name": "kidney",
        "mesh": {"file": "data:meshes/tet/kidney_57k.node", "scale": 1e-3, "axes": ["x", "z", "-y"]},
        "density": 1050.0,
        "material": "corotational", "youngs_modulus": 2e4, "poisson_ratio": 0.45,
        "velocity_damping": 2.0,
        "pinned": [{"min": [-1e3, -1e3, -1e3], "max": [1e3, math.nextafter(rest, -math.inf), 1e3]}],
    }],
    "fluid": {
        "settings": {"spacing": SPACING, "rest_density": RHO, "speed_of_sound": 5.0,
                     "time_step": FRAME / STEPS_PER_FRAME, "viscosity": 0.2},
        "capacity": 5000,
        "emitters": [vessel_at(0.0)],
        "sinks": [suction_at(0.0), {"centre": drain_centre, "radius": DRAIN_BALL}],
        "surfaces": [{"body_kind": "tet", "body": 0,
                      "any_vertex_in": [{"min": [-1e3, drain_level - 8e-3, -1e3], "max": [1e3, 1e3, 1e3]}]}],
    },
    "script": {"actions": actions},
}
scene_json.write(scene, sys.stdout)
