#!/usr/bin/env python3
"""`sinew view` headless (docs/viewer.md): under xvfb-run (Mesa's software
OpenGL) the viewer's --script-test opens a scene, lets it settle, saves a
picture, waits as long again and saves another, moves the virtual haptic
device's handle and saves a third. Checks: the pictures show a scene (many
colours, a good share of pixels off the background); moving the handle
changes the picture more than waiting does; the tool followed the handle
through the haptic loop and the physics.

Usage: view_headless_test.py SINEW_PROGRAM SCENE WORK_DIR
Exit 77 (ctest's skip) when xvfb-run is missing.
"""
import collections
import pathlib
import re
import shutil
import subprocess
import sys


def read_ppm(path):
    data = path.read_bytes()
    magic, size, maxval, pixels = data.split(b"\n", 3)
    if magic != b"P6" or maxval != b"255":
        sys.exit(f"{path}: not an 8-bit binary PPM")
    width, height = map(int, size.split())
    if len(pixels) != width * height * 3:
        sys.exit(f"{path}: {len(pixels)} bytes of pixels for {width} x {height}")
    return width, height, [pixels[i:i + 3] for i in range(0, len(pixels), 3)]


def changed_share(a, b):
    return sum(1 for p, q in zip(a, b) if max(abs(x - y) for x, y in zip(p, q)) > 8) / len(a)


def main():
    program, scene, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
    if shutil.which("xvfb-run") is None:
        print("xvfb-run not found (apt-get install xvfb xauth): skipped")
        return 77
    shutil.rmtree(work, ignore_errors=True)
    move = (0.04, -0.02, 0.0)
    command = ["xvfb-run", "-a", "-s", "-screen 0 1024x768x24", program, "view", scene, "--backend", "cpu",
               "--width", "640", "--height", "400", "--script-test", str(work),
               "--move-tool", ",".join(map(str, move))]
    run = subprocess.run(command, capture_output=True, text=True, timeout=540)
    print(run.stdout, run.stderr, sep="")
    if run.returncode != 0:
        sys.exit(f"sinew view exited with {run.returncode}")

    found = re.search(r"handle moved ([0-9.]+) m; tool (\d+) moved ([0-9.]+) m", run.stdout)
    if not found:
        sys.exit("no 'handle moved ... tool ... moved' line")
    handle, tool = float(found.group(1)), float(found.group(3))
    if abs(handle - sum(x * x for x in move) ** 0.5) > 1e-4:
        sys.exit(f"the handle moved {handle} m, not the {move} asked for")
    if tool < 0.5 * handle:
        sys.exit(f"the tool moved {tool} m after the handle moved {handle} m: it did not follow")

    shots = {name: read_ppm(work / f"{name}.ppm") for name in ("before", "still", "after")}
    width, height, before = shots["before"]
    if (width, height) != (640, 400):
        sys.exit(f"before.ppm is {width} x {height}, not the window's 640 x 400")
    colours = collections.Counter(before)
    background, count = colours.most_common(1)[0]
    off_background = 1 - count / len(before)
    print(f"before.ppm: {len(colours)} colours, {off_background:.1%} of the pixels off the background")
    if len(colours) < 64 or off_background < 0.02:
        sys.exit("before.ppm looks blank")
    waited = changed_share(before, shots["still"][2])
    moved = changed_share(shots["still"][2], shots["after"][2])
    print(f"pixels changed: {waited:.2%} by waiting, {moved:.2%} by moving the handle")
    if moved < max(0.002, 3 * waited):
        sys.exit("moving the handle did not change the picture more than waiting did")
    return 0


if __name__ == "__main__":
    sys.exit(main())
