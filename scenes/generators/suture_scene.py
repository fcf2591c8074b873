#!/usr/bin/env python3
"""Writes scenes/suture_scene.json: the reference scene S3
(examples/suture_scene.cpp, examples/common/suture_scene.h) as a scene file.

A pad of 27 x 8 x 16 cells of 2 mm with a 2 mm slit, a curved needle and its
100 mm thread of 200 segments turned through both lips twice, then pulled
until the thread's knot holds at the first puncture, 10 frames more, and
held 30; mesh collision with the thread's continuous collision. The example
reads when the knot holds from the running scene; a file cannot, so the
pull's length is the one the example measures (its frame 561 at the scene's
16 substeps x 2 iterations: `suture_scene --backend cpu` prints "the knot
held from frame 561"). The needle's poses are keyed at every frame with the
values the example computes (suture_path.py), so the scene runs bitwise as
the example.

    scenes/generators/suture_scene.py > scenes/suture_scene.json
"""
import sys

import scene_json
from suture_path import ABOVE, RADIUS, STITCH_Z, keys as needle_keys, needle, pad

CELL = 0.002
NX, NY, NZ = 27, 8, 16
SLIT_COLUMN = (NX - 1) // 2  # the 2 mm slit: one column of cells in the middle
THREAD_SEGMENTS, THREAD_LENGTH, THREAD_MASS = 200, 0.1, 1e-3
TIGHTEN, HOLD = 10, 30
KNOT_FRAME = 561  # measured: the example's "the knot held from frame 561"

piece = THREAD_LENGTH / THREAD_SEGMENTS
keys = needle_keys(KNOT_FRAME, TIGHTEN, HOLD)
scene = {
    "format": "sinew-scene",
    "version": 1,
    "description": "The reference scene S3: two stitches across a 2 mm slit in a pad of 20,064 tets, the needle's "
                   "200-segment thread pulled until its knot holds, with mesh collision and the thread's continuous "
                   "collision (examples/suture_scene.cpp; written by scenes/generators/suture_scene.py). The pull "
                   "lasts as long as the example's (it reads when the knot holds: frame 561).",
    "run": {"frames": len(keys), "every": 20},
    "gravity": [0.0, 0.0, 0.0],
    "solver": {"time_step": 1.0 / 60.0, "substeps": 16, "iterations": 2},
    "tet_bodies": [pad(NX, NY, NZ, CELL, SLIT_COLUMN)],
    "line_bodies": [{
        "name": "thread",
        "vertices": [[RADIUS, ABOVE + piece * i, STITCH_Z[0]] for i in range(THREAD_SEGMENTS + 1)],
        "mass": THREAD_MASS / (THREAD_SEGMENTS + 1),
        "bending_compliance": 10.0,
        "velocity_damping": 5.0,
    }],
    "needles": [needle(0.01)],
    "mesh_collision": {"enabled": True, "thickness": 5e-4, "self_collision": False, "continuous": True},
    "script": {"poses": [{"needle": 0, "keys": keys}]},
}
scene_json.write(scene, sys.stdout)
