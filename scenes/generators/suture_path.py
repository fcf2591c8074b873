"""The running suture's needle path, shared by suturing.py and suture_scene.py:
examples/common/suture_scene.h's suture_script(f, pulled) (two turns about the
cut at z = -3 and 3 mm with a shift between them, then up and away), computed
with the same IEEE doubles and C library as the examples."""
import math

RADIUS, ABOVE = 0.008, 0.002  # the needle's radius and its centre over the cut [m]
STITCH_Z = [-0.003, 0.003]    # [m]
TURN, SHIFT = 110, 40         # frames
STITCHED = 2 * TURN + SHIFT
PULL_SPEED = 4.25e-4          # [m per frame]
LAST_ANGLE = 2.0 * math.pi - 0.2


def script(f, pulled):
    """The needle's position and angle about z in the example's frame f (from 0)."""
    second = TURN + SHIFT
    if f < TURN:
        return [0.0, ABOVE, STITCH_Z[0]], LAST_ANGLE * (f + 1) / TURN
    if f < second:
        u = float(f - TURN + 1) / SHIFT
        return [0.0, ABOVE, STITCH_Z[0] + u * (STITCH_Z[1] - STITCH_Z[0])], LAST_ANGLE
    if f < STITCHED:
        return [0.0, ABOVE, STITCH_Z[1]], LAST_ANGLE + LAST_ANGLE * (f - second + 1) / TURN
    return [0.5 * pulled, ABOVE + pulled, STITCH_Z[1]], 2.0 * LAST_ANGLE


def keys(knot_frame, tighten, hold):
    """The needle's pose keys at every frame of the whole script: the example
    pulls until the knot holds at the first puncture (its frame knot_frame,
    counted from 0), then tighten frames more, and holds hold frames. The
    example's frame f is the runner's frame f + 1."""
    out, pulled = [], 0.0
    for f in range(knot_frame + tighten + hold + 1):
        position, angle = script(f, pulled)
        out.append({"frame": f + 1, "position": position,
                    "rotation": [math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2)]})
        if f >= STITCHED and f < knot_frame + tighten:
            pulled += PULL_SPEED
    return out


def needle(puncture_force):
    """The curved needle: a half circle of RADIUS in 16 pieces, its thread line body 0."""
    return {"curve": [[RADIUS * math.cos(math.pi * i / 16), RADIUS * math.sin(math.pi * i / 16), 0.0] for i in range(17)],
            "position": [0.0, ABOVE, STITCH_Z[0]],
            "puncture_force": puncture_force,
            "thread": 0}


def pad(nx, ny, nz, cell, slit_column):
    """The pad both suture scenes stitch: a grid of nx x ny x nz cells centred
    on x = 0 and z = 0 with its top at y = 0, the cells of column slit_column
    above the bottom layer removed (the slit), edge network of 30 kPa and nu
    0.45, damped 5/s, pinned at its two ends in x and its base."""
    half_x = nx * cell / 2
    slit_lo = -half_x + slit_column * cell
    return {
        "name": "pad",
        "mesh": {"grid": {"cells": [nx, ny, nz], "origin": [-half_x, -ny * cell, -nz * cell / 2],
                          "cell_size": [cell, cell, cell]},
                 "remove": [{"min": [slit_lo, -(ny - 1) * cell, -1.0], "max": [slit_lo + cell, 1.0, 1.0]}]},
        "elastic": {"youngs_modulus": 3e4, "poisson_ratio": 0.45},
        "velocity_damping": 5.0,
        "pinned": [{"min": [-1.0, -1.0, -1.0], "max": [-half_x + 1e-9, 1.0, 1.0]},
                   {"min": [half_x - 1e-9, -1.0, -1.0], "max": [1.0, 1.0, 1.0]},
                   {"min": [-1.0, -1.0, -1.0], "max": [1.0, -ny * cell + 1e-9, 1.0]}],
    }
