#!/usr/bin/env python3
"""How far a run's particles lie from a reference run's: the RMS and the
largest distance [mm] over particles FIRST to LAST (all by default).

    compare_positions.py REFERENCE.f32 RUN.f32 [FIRST LAST]

Both files are float32 x, y, z, w per particle (read_positions' layout), as
bench_suture_scene --positions writes them."""
import math
import struct
import sys


def read(path):
    with open(path, "rb") as f:
        data = f.read()
    values = struct.unpack("<%df" % (len(data) // 4), data)
    return [values[i:i + 3] for i in range(0, len(values), 4)]


reference, run = read(sys.argv[1]), read(sys.argv[2])
if len(reference) != len(run):
    sys.exit("the runs have %d and %d particles" % (len(reference), len(run)))
first = int(sys.argv[3]) if len(sys.argv) > 3 else 0
last = int(sys.argv[4]) if len(sys.argv) > 4 else len(run)
d = [math.dist(a, b) for a, b in zip(reference[first:last], run[first:last])]
print("rms_mm=%.4f max_mm=%.4f particles=%d" % (1e3 * math.sqrt(sum(x * x for x in d) / len(d)), 1e3 * max(d), len(d)))
