#!/usr/bin/env python3
"""Writes scenes/haptic_drag.json: examples/haptic_drag.cpp as a scene file.

The example's probe is a tool (0.5 kg) pulled by a virtual coupling to a
scripted haptic device, in a 1 kHz haptic loop paced to the wall clock; a
scene file has no haptic loop, so its probe is a kinematic capsule that
follows the device's scripted path itself (its cosine ramps, a key at every
physics frame while it moves): no coupling spring, no lag, no force fed back.

    scenes/generators/haptic_drag.py > scenes/haptic_drag.json
"""
import math
import sys

import scene_json
from motion import ramp

CELL = 0.004
TOP = 5 * CELL
RADIUS, HALF_HEIGHT = 0.006, 0.015
START_Y = TOP + 0.005 + RADIUS + HALF_HEIGHT
PRESS, DRAG, DURATION, DT = 0.012, 0.02, 5.0, 1.0 / 250.0
# The ramps' spans [s]: press, drag, lift.
RAMPS = [(0.5, 1.5), (2.0, 3.5), (4.0, 4.6)]


def hand(t):
    """The example's scripted hand: hold, press down, hold, drag along x, hold, lift."""
    x = -0.01 + DRAG * ramp(t, 2.0, 3.5)
    y = START_Y - PRESS * (ramp(t, 0.5, 1.5) - ramp(t, 4.0, 4.6))
    return [x, y, 0.0]


frames = round(DURATION / DT)
keys = []
for f in range(frames + 1):
    t = f * DT
    # Holds need only their ends: a key at every frame inside a ramp and at its ends.
    if f in (0, frames) or any(a - DT <= t <= b + DT for a, b in RAMPS):
        keys.append({"frame": f, "position": hand(t)})

scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "A rigid probe pressed 12 mm into a block of soft tissue (300 kPa) and dragged 2 cm across it "
                   "(examples/haptic_drag.cpp; written by scenes/generators/haptic_drag.py). Differences from the "
                   "example: the example drives a 0.5 kg tool through a virtual coupling from a scripted haptic "
                   "device in the real 1 kHz haptic loop, paced to the wall clock; a real-time haptic loop is not "
                   "part of a scene file, so here the device's scripted path is the probe's keyframed pose (a "
                   "kinematic capsule collider with the tool's friction): no coupling stretch, no force rendered "
                   "to a device, and the same result on every run.",
    "run": {"frames": frames, "every": 25},
    "gravity": [0.0, -9.81, 0.0],
    "solver": {"time_step": DT, "substeps": 5, "iterations": 2, "measure_errors": False},
    "tet_bodies": [{
        "name": "tissue",
        "mesh": {"grid": {"cells": [16, 5, 16], "origin": [-8 * CELL, 0.0, -8 * CELL],
                          "cell_size": [CELL, CELL, CELL]}},
        "density": 1000.0,
        "elastic": {"youngs_modulus": 300e3, "poisson_ratio": 0.4},
        "pinned": [{"min": [-1.0, -1.0, -1.0], "max": [1.0, 1e-9, 1.0]}],
    }],
    "colliders": [{"shape": "capsule", "radius": RADIUS, "half_height": HALF_HEIGHT, "position": hand(0.0),
                   "static_friction": 0.4, "dynamic_friction": 0.3}],
    "script": {"poses": [{"collider": 0, "keys": keys}]},
}
scene_json.write(scene, sys.stdout)
