#!/usr/bin/env python3
"""Writes scenes/bone_burr.json: examples/bone_burr.cpp as a scene file.

The example drives a burr (a level-set tool, 30 g, its penalty against the
bone) through a virtual coupling from a scripted haptic device, ticked in
lockstep with the physics at 1 kHz, and removes the bone the burr's own
motion sweeps. A scene file has no haptic loop: here the device's scripted
path is the burr's keyframed pose (a kinematic level-set collider, a key
every 10 ms) and the bone is cut along that path (a cut_collider action
every 10 ms, the example's cutter). The path follows the plateau's height
along the groove, which the example samples from its level set and this
from the STL's triangles (within a voxel of it).

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
EVERY = 10  # ticks between keys and cuts


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
keys, actions = [], []
last = hand(0.0)
for tick in range(0, ticks + 1, EVERY):
    at = hand(tick * TICK)
    keys.append({"frame": tick, "position": at})
    if tick > 0 and at != last:
        actions.append({"frame": tick, "do": "cut_collider", "collider": 0,
                        "cutter": {"kind": "sphere", "radius": RADIUS - CUT_DEPTH},
                        "from": {"position": last}, "to": {"position": at}})
    last = at

scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "A burr cuts a 10 mm groove across the tibia's plateau (examples/bone_burr.cpp; written by "
                   "scenes/generators/bone_burr.py). Differences from the example: the example drives a 30 g "
                   "level-set tool through a virtual coupling from a scripted haptic device in a 1 kHz haptic loop, "
                   "and removes the bone the tool's own motion sweeps (the bone's penalty holds it back: the "
                   "coupling stretches and the groove is shallower than the hand's path); a haptic loop is not part "
                   "of a scene file, so here the example's burr tool is declared but not driven (it stays at its "
                   "start, 3 mm above the plateau), and a kinematic level-set ball (collider 1) follows the device's path (a key "
                   "every 10 ms) and the bone is cut along that path (every 10 ms): the full 4 mm deep groove, no "
                   "force rendered. The bone keeps its whole inside to 5 cm (the example: an unbounded band); the "
                   "path's heights come from the STL's triangles (the example samples its level set).",
    "run": {"frames": ticks, "every": 500},
    "gravity": [0.0, 0.0, -9.81],
    "solver": {"time_step": TICK, "substeps": 1, "iterations": 1, "measure_errors": False},
    "colliders": [
        {"shape": "level_set",
         "level_set": {"file": "data:" + stl, "scale": 1e-3, "voxel_size": VOXEL, "exterior_band": 3.0 * VOXEL,
                       "interior_band": 0.05}},
        {"shape": "level_set", "position": hand(0.0),
         "level_set": {"sphere": {"centre": [0.0, 0.0, 0.0], "radius": RADIUS}, "voxel_size": RADIUS / 8,
                       "exterior_band": RADIUS / 2, "interior_band": RADIUS}},
    ],
    # The example's burr, as it declares it: with no haptic loop to pull it,
    # it stays where it starts, 3 mm above the plateau (gravity off).
    "tools": [{"shape": "level_set", "position": hand(0.0), "gravity": False,
               "level_set": {"sphere": {"centre": [0.0, 0.0, 0.0], "radius": RADIUS}, "voxel_size": RADIUS / 8,
                             "exterior_band": RADIUS / 2, "interior_band": RADIUS},
               "penalty_stiffness": 2.66e9, "penalty_damping": 2e6, "mass": 0.03, "inertia": [2.5e-5, 2.5e-5, 2e-6]}],
    "script": {"poses": [{"collider": 1, "keys": keys}], "actions": actions},
}
scene_json.write(scene, sys.stdout)
