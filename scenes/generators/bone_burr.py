#!/usr/bin/env python3
"""Writes scenes/bone_burr.json: examples/bone_burr.cpp as a scene file.

A scripted haptic device drives the burr (a level-set tool, 30 g, its
penalty against the bone) through a virtual coupling, its haptic loop ticked
in lockstep with the physics at 1 kHz on a virtual clock; the burr cuts the
bone along its own motion after every frame (the tool's "cuts"). The hand's
path follows the plateau's height along the groove, taken from the STL's
triangles with the example's arithmetic, as keys every 10 ms (straight
lines between them), so `sinew run` and the example give the same run.

    scenes/generators/bone_burr.py DATA_DIR > scenes/bone_burr.json

DATA_DIR: the data folder (data/ or a build's data folder).
"""
import math
import os
import struct
import sys

import scene_json
from motion import ramp

RADIUS, CUT_DEPTH, VOXEL = 2e-3, 1e-4, 2.5e-4
TICK = 1e-3
ABOVE, BELOW, LIFT, GROOVE = 3e-3, 4e-3, 8e-3, 0.01
DOWN, ALONG, UP = 1.5, 4.0, 1.0
DURATION = 0.3 + DOWN + ALONG + UP + 0.2
EVERY = 10  # ticks between the path's keys


def read_stl(path):
    """A binary STL's triangles, each three vertices in metres."""
    with open(path, "rb") as f:
        data = f.read()
    count = struct.unpack_from("<I", data, 80)[0]
    return [[[c * 1e-3 for c in struct.unpack_from("<3f", data, 84 + 50 * t + 12 + 12 * k)] for k in range(3)]
            for t in range(count)]


data = sys.argv[1] if len(sys.argv) > 1 else "data"
stl = "meshes/surface/VHF_Left_Bone_Tibia_smooth.stl"
triangles = read_stl(os.path.join(data, stl))
points = [p for t in triangles for p in t]
top = list(max(points, key=lambda p: p[2]))
lo = [min(p[k] for p in points) for k in range(3)]
hi = [max(p[k] for p in points) for k in range(3)]
for k in range(2):  # 5 mm towards the bone's middle
    top[k] += 5e-3 if top[k] < 0.5 * (lo[k] + hi[k]) else -5e-3
y0 = top[1] - 0.5 * GROOVE

# The surface's height at (top x, y): the highest triangle over it below top z + 5 mm.
near = [t for t in triangles if min(p[0] for p in t) <= top[0] <= max(p[0] for p in t)
        and max(p[1] for p in t) >= y0 - 1e-3 and min(p[1] for p in t) <= y0 + GROOVE + 1e-3]


def surface_at(y):
    best = -math.inf
    for a, b, c in near:
        d = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1])
        if d == 0.0:
            continue
        u = ((b[1] - c[1]) * (top[0] - c[0]) + (c[0] - b[0]) * (y - c[1])) / d
        v = ((c[1] - a[1]) * (top[0] - c[0]) + (a[0] - c[0]) * (y - c[1])) / d
        if u < 0.0 or v < 0.0 or u + v > 1.0:
            continue
        z = u * a[2] + v * b[2] + (1.0 - u - v) * c[2]
        if z <= top[2] + 5e-3:
            best = max(best, z)
    return best


height = [surface_at(y0 + i * GROOVE / 100) for i in range(101)]


def surface_z(y):
    u = min(max((y - y0) / GROOVE * 100, 0.0), 100.0)
    i = min(int(u), 99)
    return height[i] + (u - i) * (height[i + 1] - height[i])


def hand(t):
    """The example's scripted hand: down into the plateau, along the groove, out."""
    y = y0 + GROOVE * ramp(t, 0.3 + DOWN, 0.3 + DOWN + ALONG)
    depth = (ABOVE - (ABOVE + BELOW) * ramp(t, 0.3, 0.3 + DOWN)
             + (BELOW + LIFT) * ramp(t, 0.3 + DOWN + ALONG, DURATION - 0.2))
    return [top[0], y, surface_z(y) + depth]


ticks = round(DURATION / TICK)
keys = [{"time": tick * TICK, "position": hand(tick * TICK)} for tick in range(0, ticks + 1, EVERY)]

scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "A burr cuts a 10 mm groove across the tibia's plateau (examples/bone_burr.cpp; written by "
                   "scenes/generators/bone_burr.py). A scripted haptic device drives the 30 g burr (a level-set "
                   "tool) through a virtual coupling, its 1 kHz haptic loop ticked between the frames on a virtual "
                   "clock, and the burr removes the bone its own motion sweeps deeper than 0.1 mm (its \"cuts\"), "
                   "so the bone's push holds it back and the hand feels it: the same run as the example.",
    "run": {"frames": ticks, "every": 500},
    "gravity": [0.0, 0.0, -9.81],
    "solver": {"time_step": TICK, "substeps": 1, "iterations": 1, "measure_errors": False},
    "colliders": [
        {"shape": "level_set",
         "level_set": {"file": "data:" + stl, "scale": 1e-3, "voxel_size": VOXEL, "exterior_band": 3.0 * VOXEL,
                       "interior_band": "whole"}},
    ],
    "tools": [{"shape": "level_set", "position": hand(0.0), "gravity": False,
               "level_set": {"sphere": {"centre": [0.0, 0.0, 0.0], "radius": RADIUS}, "voxel_size": RADIUS / 8,
                             "exterior_band": RADIUS / 2, "interior_band": RADIUS},
               "penalty_stiffness": 2.66e9, "penalty_damping": 2e6, "mass": 0.03, "inertia": [2.5e-5, 2.5e-5, 2e-6],
               "cuts": {"collider": 0, "cutter": {"kind": "sphere", "radius": RADIUS - CUT_DEPTH}}}],
    "haptics": {"hands": [{
        "tool": 0,
        "path": {"interpolation": "linear", "keys": keys},
        "tool_damping": 2.0,
        "tool_angular_damping": 1e-4,
    }]},
}
scene_json.write(scene, sys.stdout)
