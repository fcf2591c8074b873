"""The examples' scripted motion, as they compute it."""
import math


def ramp(t, a, b):
    """Smooth 0 -> 1 over [a, b] (cosine ramp: zero velocity at both ends)."""
    if t <= a:
        return 0.0
    if t >= b:
        return 1.0
    return 0.5 - 0.5 * math.cos(math.pi * (t - a) / (b - a))
