#!/usr/bin/env python3
"""Writes scenes/suturing.json: examples/suturing.cpp as a scene file.

The needle's path is the example's script(f): two turns about the cut with
a shift between them, then a pull up and away at 0.425 mm a frame. The
example pulls until the thread's knot holds at the first puncture, which it
reads from the running scene, and then 10 frames more and holds 60; a scene
file cannot read the scene, so the pull's length is the one the example
measures (the knot holds at its frame 538 on every backend, which agree
bitwise). The poses are keyed at every frame, with the values the example
computes (Python's floats are the same IEEE doubles and its math.cos and
math.sin the same C library's), so the scene runs bitwise as the example.

    scenes/generators/suturing.py > scenes/suturing.json
"""
import json
import sys

from suture_path import ABOVE, RADIUS, STITCH_Z, keys as needle_keys, needle, pad

CELL = 0.002
NX, NY, NZ, SLIT = 13, 5, 6, 6
THREAD_SEGMENTS = 100
TIGHTEN, HOLD = 10, 60
KNOT_FRAME = 538  # measured: the example's "frame 538  the knot holds at the first puncture"

keys = needle_keys(KNOT_FRAME, TIGHTEN, HOLD)
last = KNOT_FRAME + TIGHTEN + HOLD
scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "Two stitches across a slit in a pad, tightened: a needle turned about the cut twice, "
                   "its thread following through the punctures, then pulled until the knot holds "
                   "(examples/suturing.cpp; written by scenes/generators/suturing.py).",
    "run": {"frames": last + 1, "every": 10, "backend": "auto"},
    "gravity": [0.0, 0.0, 0.0],
    "solver": {"time_step": 1.0 / 60.0, "substeps": 8, "iterations": 10},
    "tet_bodies": [pad(NX, NY, NZ, CELL, SLIT)],
    "line_bodies": [{
        "name": "thread",
        "vertices": [[RADIUS, ABOVE + 0.001 * i, STITCH_Z[0]] for i in range(THREAD_SEGMENTS + 1)],
        "mass": 1e-5,
        "bending_compliance": 10.0,
        "velocity_damping": 5.0,
    }],
    "needles": [needle(0.01)],
    "script": {"poses": [{"needle": 0, "keys": "KEYS"}]},
}
one_line = ",\n   ".join(json.dumps(k) for k in keys)
sys.stdout.write(json.dumps(scene, indent=1).replace('"KEYS"', "[\n   " + one_line + "\n  ]") + "\n")
