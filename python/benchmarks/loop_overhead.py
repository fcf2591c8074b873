#!/usr/bin/env python3
"""What a Python loop costs over a C++ loop: the same scene, in the same
process and module, stepped N frames by sim.run(N) (the loop in C++) and by
`for _ in range(N): sim.step()` (the loop in Python: a call, the GIL
released and taken back, a FrameStats copied to Python per frame), each
timed by time.perf_counter around the whole loop, alternating which goes
first, several runs; the overhead is the ratio of the medians. With
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


def loop_ms(scene, backend, threads, frames, in_python):
    """Wall time per frame [ms] of `frames` frames stepped in a C++ or a Python loop."""
    sim = sinew.Simulation(scene, backend=backend, threads=threads)
    sim.step()  # the first frame (the CPU team's first timings) is not the loop's
    start = time.perf_counter()
    if in_python:
        for _ in range(frames):
            sim.step()
    else:
        sim.run(frames)
    return (time.perf_counter() - start) * 1e3 / frames


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default="scenes/tissue_sag.json")
    parser.add_argument("--backend", default="cpu")
    parser.add_argument("--frames", type=int, default=10000)
    parser.add_argument("--runs", type=int, default=5, help="runs of each loop, alternating")
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
    cpp, py, runner = [], [], []
    for r in range(args.runs):
        # Alternate which goes first, so a drift in the machine's load hits both alike.
        for in_python in ((False, True) if r % 2 == 0 else (True, False)):
            (py if in_python else cpp).append(loop_ms(scene, args.backend, args.threads, args.frames, in_python))
        if args.runner:
            runner.append(runner_mean_ms(args.runner, args.scene, args.backend, args.threads, args.frames))
        print(f"run {r + 1}: C++ loop {cpp[-1]:.4f} ms/frame, Python loop {py[-1]:.4f} ms/frame "
              f"({100 * (py[-1] / cpp[-1] - 1):+.2f}%)" + (f", runner {runner[-1]:.4f}" if runner else ""), flush=True)
    c, p = statistics.median(cpp), statistics.median(py)
    print(f"median of {args.runs} runs of {args.frames} frames of {args.scene}"
          + (f" with {args.cells} cells" if args.cells else "") + f" on {args.backend}: "
          f"C++ loop {c:.4f} ms/frame, Python loop {p:.4f} ms/frame ({100 * (p / c - 1):+.2f}%, "
          f"{1e3 * (p - c):+.1f} us/frame)" + (f"; runner mean {statistics.median(runner):.4f} ms/frame" if runner else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
