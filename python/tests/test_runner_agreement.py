"""Python's Simulation computes what `sinew run` computes, bit for bit: the
same scene file, script and backend give the same final positions."""
import numpy as np
import pytest

import sinew
from conftest import make_simulation


@pytest.mark.parametrize("backend", ["cpu", "opencl", "vulkan"])
def test_flagship_five_frames_equal_the_runner(scenes, runner_positions, backend):
    scene = sinew.load_scene_file(scenes / "tissue_sag.json")
    sim = make_simulation(scene, backend)
    for _ in range(5):
        sim.step()
    ours = sim.read_positions()
    theirs = runner_positions(scenes / "tissue_sag.json", backend, 5)
    assert ours.shape == theirs.shape == (sim.info.particles, 4)
    # Bitwise: the raw bytes, so NaNs or signed zeros could not hide a difference.
    assert ours.tobytes() == theirs.tobytes()
    # The scene moved at all (a comparison of two unstepped states would prove nothing).
    assert not np.array_equal(ours, sinew.Simulation(scene, backend="cpu").read_positions())


def test_scripted_scene_equals_the_runner(scenes, runner_positions):
    # grasp_and_cut's script grasps (frame 1), lifts, releases (50), cuts (60)
    # and burns (70): run() must play it as the runner does.
    scene = sinew.load_scene_file(scenes / "grasp_and_cut.json")
    sim = sinew.Simulation(scene, backend="cpu")
    sim.run(75)
    assert sim.frame == 75
    assert sim.read_positions().tobytes() == runner_positions(scenes / "grasp_and_cut.json", "cpu", 75).tobytes()


def test_without_the_script_the_scene_differs(scenes):
    scene = sinew.load_scene_file(scenes / "grasp_and_cut.json")
    played = sinew.Simulation(scene, backend="cpu")
    unplayed = sinew.Simulation(scene, backend="cpu", play_script=False)
    played.step()
    unplayed.step()
    assert [e.kind for e in played.events] == ["close_grasper"]
    assert unplayed.events == []
    played.run(9)
    unplayed.run(9)
    assert not np.array_equal(played.read_positions(), unplayed.read_positions())


def test_scripted_hands_equal_the_runner(scenes, runner_positions):
    # haptic_drag's probe is driven by a scripted hand through the haptic
    # loop, ticked between the frames: Python plays it as the runner does.
    scene = sinew.load_scene_file(scenes / "haptic_drag.json")
    sim = sinew.Simulation(scene, backend="cpu")
    sim.run(400)  # through the press (0.5-1.5 s) into the drag
    assert sim.read_positions().tobytes() == runner_positions(scenes / "haptic_drag.json", "cpu", 400).tobytes()
    # Without the hand the probe stays where it starts: the tissue only sags.
    still = sinew.Simulation(scene, backend="cpu", play_script=False)
    still.run(400)
    assert not np.array_equal(sim.read_positions(), still.read_positions())
