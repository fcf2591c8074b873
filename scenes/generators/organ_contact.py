#!/usr/bin/env python3
"""Writes scenes/organ_contact.json: examples/organ_contact.cpp as a scene file.

The example places the kidney from both meshes' bounds (above the liver's
middle, 3 mm clear of the liver under its footprint), pins the liver's
lowest fifth and starts its probe 5 mm above the kidney's highest point;
this computes the same numbers from the same meshes (Python's floats are
the same IEEE doubles) and writes them: the kidney's "translate", the pin
box (its top the largest double below the example's strict bound) and the
probe's start. The example moves its probe over a quarter of however many
frames it runs; the scene holds its default 60 frames' path, a key at
every frame with the example's value.

    scenes/generators/organ_contact.py DATA_DIR > scenes/organ_contact.json

DATA_DIR: a build's data folder (the meshes unpacked, e.g. build/data).
"""
import math
import os
import sys

import scene_json
from mesh_files import read_node

FRAMES = 60


def bounds(vertices):
    return ([min(v[k] for v in vertices) for k in range(3)], [max(v[k] for v in vertices) for k in range(3)])


data = sys.argv[1] if len(sys.argv) > 1 else "build/data"
liver = [[c * 1e-3 for c in v] for v in read_node(os.path.join(data, "meshes/tet/liver_382k.node"))]
kidney = [[c * 1e-3 for c in v] for v in read_node(os.path.join(data, "meshes/tet/kidney_57k.node"))]
lo, hi = bounds(liver)
klo, khi = bounds(kidney)
cx, cz = 0.5 * (lo[0] + hi[0]), 0.5 * (lo[2] + hi[2])
hx, hz = 0.5 * (khi[0] - klo[0]), 0.5 * (khi[2] - klo[2])
under = lo[1]
for v in liver:
    if abs(v[0] - cx) <= hx and abs(v[2] - cz) <= hz:
        under = max(under, v[1])
shift = [cx - 0.5 * (klo[0] + khi[0]), under + 0.003 - klo[1], cz - 0.5 * (klo[2] + khi[2])]
kidney = [[v[k] + shift[k] for k in range(3)] for v in kidney]

# The liver's pins: y < lo + 0.2 (hi - lo) in the example; a box's bounds are included.
pin_below = lo[1] + 0.2 * (hi[1] - lo[1])
pin_top = math.nextafter(pin_below, -math.inf)
assert sum(v[1] < pin_below for v in liver) == sum(v[1] <= pin_top for v in liver)

RADIUS, HALF_HEIGHT = 0.008, 0.02
s = math.sqrt(0.5)
rotation = [s, 0.0, 0.0, s]  # the capsule's y axis onto x
top = kidney[0]
for v in kidney:
    if v[1] > top[1]:
        top = v
start = [top[0], top[1] + RADIUS + 0.005, top[2]]
keys = []
for f in range(FRAMES):  # the example's frame f is the runner's f + 1
    press = min(1.0, (f + 1) / (0.25 * FRAMES))
    slide = max(0.0, (f + 1 - 0.25 * FRAMES) / (0.75 * FRAMES))
    keys.append({"frame": f + 1, "position": [start[0] + 0.03 * slide, start[1] - 0.02 * press, start[2]],
                 "rotation": rotation})

scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "The kidney (kidney_57k) pressed onto the liver (liver_382k) by a kinematic capsule probe and "
                   "slid 3 cm along it, the organs touching through mesh collision (examples/organ_contact.cpp; "
                   "written by scenes/generators/organ_contact.py). The meshes are the packed ones, found by their "
                   "\"data:\" names in the build's data folder or SINEW_DATA_DIR. Differences from the example: the "
                   "kidney's placement, the liver's pins and the probe's start are the numbers the example computes "
                   "from the meshes' bounds, written out; the probe's path is the example's for its default 60 "
                   "frames (the example stretches it over however many frames it is asked for; here a shorter run "
                   "is the path's beginning). The example's options (--thickness, --self-collision, --continuous) "
                   "are mesh_collision's keys here, at the example's defaults.",
    "run": {"frames": FRAMES, "every": 10},
    "gravity": [0.0, 0.0, 0.0],
    "solver": {"time_step": 1.0 / 60.0, "substeps": 10, "iterations": 5, "measure_errors": False},
    "tet_bodies": [
        {"name": "liver", "mesh": {"file": "data:meshes/tet/liver_382k.node", "scale": 1e-3},
         "elastic": {"youngs_modulus": 5e4, "poisson_ratio": 0.4}, "density": 1060.0, "velocity_damping": 5.0,
         "pinned": [{"min": [-1e3, -1e3, -1e3], "max": [1e3, pin_top, 1e3]}]},
        {"name": "kidney", "mesh": {"file": "data:meshes/tet/kidney_57k.node", "scale": 1e-3, "translate": shift},
         "elastic": {"youngs_modulus": 5e4, "poisson_ratio": 0.4}, "density": 1060.0, "velocity_damping": 5.0},
    ],
    "mesh_collision": {"enabled": True, "thickness": 1e-3, "self_collision": False, "self_culling": True,
                       "continuous": False},
    "colliders": [{"shape": "capsule", "radius": RADIUS, "half_height": HALF_HEIGHT, "position": start,
                   "rotation": rotation}],
    "script": {"poses": [{"collider": 0, "keys": keys}]},
}
scene_json.write(scene, sys.stdout)
