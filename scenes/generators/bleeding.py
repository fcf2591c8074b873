#!/usr/bin/env python3
"""Writes scenes/bleeding.json: examples/bleeding.cpp as a scene file.

The example's pulsing flow (1 ml/s, +-50% at 1.2 Hz) and its suction tip's
path (down 8 mm in 0.3 s from 1.5 s, then a sweep along z as a sine) are
functions of time that no keyframe interpolates exactly, so the script
sets the emitter and the sink before every frame, with the values the
example computes (Python's floats are the same IEEE doubles and its
math.sin the same C library's): the scene runs bitwise as the example.

    scenes/generators/bleeding.py > scenes/bleeding.json
"""
import json
import math
import sys

CELL, SPACING, FRAME = 2e-3, 1e-3, 2e-3
SECONDS, FLOW_ML = 3.0, 1.0
PI = 3.14159265358979323846
PARKED = [0.0, 1.0, 0.0]
VESSEL = {"centre": [7.5e-3, 9e-3, 16e-3], "direction": [1, -0.3, 0], "radius": 1.5e-3}

frames = round(SECONDS / FRAME)
actions = []
for frame in range(1, frames + 1):
    t = frame * FRAME
    flow = FLOW_ML * 1e-6 * (1.0 + 0.5 * math.sin(2.0 * PI * 1.2 * t))
    actions.append(dict({"frame": frame, "do": "set_emitter", "emitter": 0}, **VESSEL, flow_rate=flow))
    tip = PARKED
    if t >= 1.5:
        down, sweep = min((t - 1.5) / 0.3, 1.0), max(t - 1.8, 0.0)
        tip = [20e-3, 16e-3 - 8e-3 * down, 16e-3 + 6e-3 * math.sin(2.0 * PI * 0.5 * sweep)]
    actions.append({"frame": frame, "do": "set_sink", "sink": 0, "centre": tip, "radius": 3e-3})

scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "Blood from a cut vessel fills a pit in tissue, and a suction tip removes it "
                   "(examples/bleeding.cpp; written by scenes/generators/bleeding.py).",
    "run": {"frames": frames, "every": 25, "backend": "auto"},
    "solver": {"time_step": FRAME, "substeps": 4, "iterations": 8},
    "tet_bodies": [{
        "name": "tissue",
        # A 32 x 12 x 32 mm block of 2 mm cells with the pit's cells [3, 13) x [2, 6) x [3, 13) removed.
        "mesh": {"grid": {"cells": [16, 6, 16], "cell_size": [CELL, CELL, CELL]},
                 "remove": [{"min": [3 * CELL, 2 * CELL, 3 * CELL], "max": [13 * CELL, 1.0, 13 * CELL]}]},
        "density": 1060.0,
        "elastic": {"youngs_modulus": 2e4, "poisson_ratio": 0.45},
        "stiffness_damping": 0.01,
        "pinned": [{"min": [-1.0, -1.0, -1.0], "max": [1.0, 1e-9, 1.0]}],
    }],
    "fluid": {
        "settings": {"spacing": SPACING, "rest_density": 1060.0, "speed_of_sound": 5.0, "time_step": 1.25e-4,
                     "viscosity": 0.2},
        "capacity": 8000,
        "emitters": [dict(VESSEL, flow_rate=FLOW_ML * 1e-6)],
        "sinks": [{"centre": PARKED, "radius": 3e-3}],
        # The surface the blood can reach: the pit's walls and floor and the block's top.
        "surfaces": [{"body_kind": "tet", "body": 0, "centroid_in": [
            {"min": [5.9e-3, 3.9e-3, 5.9e-3], "max": [26.1e-3, 1.0, 26.1e-3]},
            {"min": [-1.0, 11.9e-3, -1.0], "max": [1.0, 1.0, 1.0]}]}],
    },
    "script": {"actions": actions},
}
# One action a line: the static part indented, the 3,000 actions compact.
scene["script"]["actions"] = "ACTIONS"
one_line = ",\n   ".join(json.dumps(a) for a in actions)
sys.stdout.write(json.dumps(scene, indent=1).replace('"ACTIONS"', "[\n   " + one_line + "\n  ]") + "\n")
