#!/usr/bin/env python3
"""Writes scenes/haptic_drag.json: examples/haptic_drag.cpp as a scene file.

The probe is a tool (0.5 kg) pulled by a virtual coupling to a scripted
haptic device whose path is the example's keys (cosine ramps between them);
the runner ticks the device's 1 kHz haptic loop between the frames on a
virtual clock, as `haptic_drag --clock virtual` does, so the two runs are
the same bit for bit.

    scenes/generators/haptic_drag.py > scenes/haptic_drag.json
"""
import sys

import scene_json

CELL = 0.004
TOP = 5 * CELL
RADIUS, HALF_HEIGHT = 0.006, 0.015
START_Y = TOP + 0.005 + RADIUS + HALF_HEIGHT
PRESS, DRAG, DURATION, DT = 0.012, 0.02, 5.0, 1.0 / 250.0
MASS = 0.5
R2, L2 = RADIUS * RADIUS, 4 * HALF_HEIGHT * HALF_HEIGHT

# The example's hand: hold, press down, hold, drag along x, hold, lift.
X0 = -0.01
X1 = X0 + DRAG
DOWN = START_Y - PRESS
KEYS = [(0.0, X0, START_Y), (0.5, X0, START_Y), (1.5, X0, DOWN), (2.0, X0, DOWN), (3.5, X1, DOWN),
        (4.0, X1, DOWN), (4.6, X1, START_Y)]

scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "A rigid probe pressed 12 mm into a block of soft tissue (300 kPa) and dragged 2 cm across it "
                   "(examples/haptic_drag.cpp; written by scenes/generators/haptic_drag.py). The probe is a 0.5 kg "
                   "tool driven through a virtual coupling by a scripted haptic device; the runner ticks its 1 kHz "
                   "haptic loop between the frames on a virtual clock, as `haptic_drag --clock virtual` does (the "
                   "example's default paces the loop's own thread to the wall clock instead).",
    "run": {"frames": round(DURATION / DT), "every": 25},
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
    "tools": [{
        "shape": "capsule", "radius": RADIUS, "half_height": HALF_HEIGHT,
        "mass": MASS,
        "inertia": [MASS * (3 * R2 + L2) / 12, MASS * R2 / 2, MASS * (3 * R2 + L2) / 12],
        "position": [X0, START_Y, 0.0],
        "gravity": False,
        "static_friction": 0.4, "dynamic_friction": 0.3,
    }],
    "haptics": {"hands": [{
        "tool": 0,
        "rate_hz": 1000.0,
        "path": {"interpolation": "smooth",
                 "keys": [{"time": t, "position": [x, y, 0.0]} for t, x, y in KEYS]},
        "coupling": {"damping": 3.0},
        "tool_damping": 5.0,
        "tool_angular_damping": 2e-3,
    }]},
}
scene_json.write(scene, sys.stdout)
