#!/usr/bin/env python3
"""Runs `sinew run SCENE --backend cpu --frames N --positions FILE` and checks
that it succeeded and wrote every particle's position (float32 xyzw, 16
bytes each), all finite.

    run_scene_finite.py RUNNER SCENE FRAMES WORK_DIR
"""
import math
import os
import struct
import subprocess
import sys

runner, scene, frames, work = sys.argv[1:5]
os.makedirs(work, exist_ok=True)
positions = os.path.join(work, os.path.basename(scene) + ".f32")
if os.path.exists(positions):
    os.remove(positions)
run = subprocess.run([runner, "run", scene, "--backend", "cpu", "--frames", frames, "--quiet", "--out", work,
                      "--positions", positions], capture_output=True, text=True)
if run.returncode != 0:
    sys.exit("sinew run failed (%d):\n%s%s" % (run.returncode, run.stdout, run.stderr))
with open(positions, "rb") as f:
    data = f.read()
if len(data) % 16 != 0:
    sys.exit("%s: %d bytes, not whole xyzw float32 particles" % (positions, len(data)))
values = struct.unpack("<%df" % (len(data) // 4), data)
bad = [i // 4 for i, v in enumerate(values) if not math.isfinite(v)]
if bad:
    sys.exit("%s: %d particles not finite after %s frames (the first: %d)" % (scene, len(set(bad)), frames, bad[0]))
print("%s: %d particles finite after %s frames" % (os.path.basename(scene), len(values) // 4, frames))
