#!/usr/bin/env python3
"""What a Python loop costs over a C++ loop: one Simulation stepped in
alternating blocks of frames, by sim.run(B) (the loop in C++) and by
`for _ in range(B): sim.step()` (the loop in Python: a call, the GIL
released and taken back, a FrameStats copied to Python per frame), each
block timed by time.perf_counter; the overhead is the median over the
pairs of blocks of Python's time over C++'s (a pair sees the same load on
a shared machine), over several runs. With
--runner it also runs `sinew run` and reports its own mean frame time (the
mean of FrameStats.wall_ms, the time inside Simulation::step only), for
reference.

    PYTHONPATH=build/python python3 python/benchmarks/loop_overhead.py \\
        --scene scenes/tissue_sag.json --frames 10000 --runs 5 [--runner build/apps/sinew/sinew]
"""
import argparse
import json
import re
import statistics
import subprocess
import sys
import time

import sinew

PROFILE = re.compile(r"profile: ([0-9.]+) ms per frame")


def runner_mean_ms(runner, scene, backend, threads, frames):
    out = subprocess.run([runner, "run", scene, "--backend", backend, "--threads", str(threads), "--frames", str(frames),
                          "--quiet"],
                         check=True, capture_output=True, text=True).stdout
    match = PROFILE.search(out)
    if not match:
        raise RuntimeError(f"no profile line in the runner's output:\n{out}")
    return float(match.group(1))


def paired_blocks(scene, backend, threads, frames, block):
    """One Simulation stepped `frames` frames in blocks of `block`, each pair
    of blocks one by run(block) (the loop in C++) and one by a Python loop of
    step(), in alternating order: the two see the same scene state and the
    same load on the machine within a pair. Returns (C++ ms/frame, Python
    ms/frame) of every pair."""
    sim = sinew.Simulation(scene, backend=backend, threads=threads)
    sim.step()  # the first frame (the CPU team's first timings) is not the loop's
    pairs = []
    for b in range(max(1, frames // (2 * block))):
        timed = {}
        for in_python in ((False, True) if b % 2 == 0 else (True, False)):
            start = time.perf_counter()
            if in_python:
                for _ in range(block):
                    sim.step()
            else:
                sim.run(block)
            timed[in_python] = (time.perf_counter() - start) * 1e3 / block
        pairs.append((timed[False], timed[True]))
    return pairs


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default="scenes/tissue_sag.json")
    parser.add_argument("--backend", default="cpu")
    parser.add_argument("--frames", type=int, default=10000)
    parser.add_argument("--runs", type=int, default=5, help="runs (each a fresh Simulation)")
    parser.add_argument("--block", type=int, default=50, help="frames per block (C++ and Python blocks alternate)")
    parser.add_argument("--threads", type=int, default=0, help="CPU worker threads (0: all)")
    parser.add_argument("--cells", type=int, nargs=3, metavar=("X", "Y", "Z"),
                        help="the first tet body's grid cells instead of the file's (a smaller block: the "
                             "binding's own cost per frame stands out)")
    parser.add_argument("--runner", help="also time `sinew run` (build/apps/sinew/sinew), for reference")
    args = parser.parse_args()
    if args.frames < 1 or args.runs < 1:
        parser.error("--frames and --runs must be >= 1")

    if args.cells and args.runner:
        parser.error("--runner runs the file as it is: not with --cells")
    if args.cells:
        with open(args.scene) as f:
            d = json.load(f)
        d["tet_bodies"][0]["mesh"]["grid"]["cells"] = args.cells
        scene = sinew.scene_from_dict(d)
    else:
        scene = sinew.load_scene_file(args.scene)
    cpp, py, ratios, runner = [], [], [], []
    for r in range(args.runs):
        pairs = paired_blocks(scene, args.backend, args.threads, args.frames, args.block)
        cpp.extend(c for c, _ in pairs)
        py.extend(p for _, p in pairs)
        ratios.extend(p / c for c, p in pairs)
        if args.runner:
            runner.append(runner_mean_ms(args.runner, args.scene, args.backend, args.threads, args.frames))
        print(f"run {r + 1}: {len(pairs)} pairs of {args.block}-frame blocks: C++ loop "
              f"{statistics.median(c for c, _ in pairs):.4f} ms/frame, Python loop "
              f"{statistics.median(p for _, p in pairs):.4f} ms/frame, Python/C++ per pair "
              f"{100 * (statistics.median(p / c for c, p in pairs) - 1):+.2f}%"
              + (f", runner {runner[-1]:.4f}" if runner else ""), flush=True)
    c, p = statistics.median(cpp), statistics.median(py)
    print(f"median over {args.runs} runs of {args.frames} frames of {args.scene}"
          + (f" with {args.cells} cells" if args.cells else "") + f" on {args.backend} ({len(ratios)} block pairs): "
          f"C++ loop {c:.4f} ms/frame, Python loop {p:.4f} ms/frame ({1e3 * (p - c):+.1f} us/frame); "
          f"Python/C++ per pair {100 * (statistics.median(ratios) - 1):+.2f}%"
          + (f"; runner mean {statistics.median(runner):.4f} ms/frame" if runner else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
