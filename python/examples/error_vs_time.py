#!/usr/bin/env python3
"""Runs a scene file and plots its solver error (the RMS normalised
constraint residual of each frame, FrameStats.residual_rms) against
simulated time, into a PNG.

    PYTHONPATH=build/python python3 python/examples/error_vs_time.py \\
        scenes/tissue_sag.json --backend cpu --frames 120 --out error_vs_time.png
"""
import argparse
import sys

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402 (after the backend is chosen)

import sinew  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", help="a scene file (scenes/*.json)")
    parser.add_argument("--out", required=True, help="the PNG to write")
    parser.add_argument("--backend", default=None, help="cpu, opencl, vulkan or auto (default: the scene's)")
    parser.add_argument("--frames", type=int, default=None, help="frames to run (default: the scene's run.frames)")
    args = parser.parse_args()
    if args.frames is not None and args.frames < 1:
        parser.error(f"--frames must be >= 1 (got {args.frames})")

    try:
        scene = sinew.load_scene_file(args.scene)
        sim = sinew.Simulation(scene, backend=args.backend)
        time, residual, volume = [], [], []
        for _ in range(args.frames or scene.frames):
            stats = sim.step()  # the scene's script is played, as `sinew run` plays it
            time.append(stats.time)
            residual.append(stats.residual_rms)
            volume.append(abs(stats.volume_change))
    except sinew.Error as e:
        print(f"error_vs_time: {e} ({e.code})", file=sys.stderr)
        return 1

    fig, ax = plt.subplots(figsize=(7, 4))
    ax.semilogy(time, residual, label="RMS normalised residual")
    ax.semilogy(time, volume, label="|volume change|", linestyle="--")
    ax.set_xlabel("simulated time [s]")
    ax.set_ylabel("error (relative)")
    ax.set_title(f"{args.scene} on {sim.backend_name}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}: {len(time)} frames, last residual {residual[-1]:.3e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
