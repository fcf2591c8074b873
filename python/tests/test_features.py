"""Tools, graspers, needles, the events of a frame, FrameStats and
SceneInfo as Python objects."""
import json
import math
import threading

import numpy as np
import pytest

import sinew


@pytest.fixture(scope="module")
def grasp_and_cut(scenes):
    """grasp_and_cut run to frame 75 with the events of every frame."""
    scene = sinew.load_scene_file(scenes / "grasp_and_cut.json")
    sim = sinew.Simulation(scene, backend="cpu")
    events, stats = [], []
    for _ in range(75):
        stats.append(sim.step())
        events.extend(sim.events)
    return sim, events, stats


def test_script_events_are_objects(grasp_and_cut):
    sim, events, _ = grasp_and_cut
    assert [(e.frame, e.kind) for e in events] == [(1, "close_grasper"), (50, "open_grasper"), (60, "cut"),
                                                   (70, "cauterize")]
    closed, opened, cut, burned = events
    assert len(closed.particles) > 0 and closed.particles.dtype == np.uint32
    assert np.array_equal(np.sort(closed.particles), np.sort(opened.particles))
    assert closed.topology is None and cut.topology is not None
    assert len(cut.topology.tets_removed) > 0 and cut.topology.body_kind == "tet"
    assert len(burned.topology.tets_removed) > 0 and burned.topology.mass_removed > 0.0
    assert cut.text.startswith("frame 60: cut:")


def test_grasper_holds_then_releases(grasp_and_cut, scenes):
    sim, _, _ = grasp_and_cut
    assert sim.graspers.count == 1
    assert sim.graspers.held_points(0) == []  # opened at frame 50
    with pytest.raises(sinew.Error) as raised:
        sim.graspers.held_points(1)
    assert raised.value.code == "bad_parameter"


def test_cut_surface_loses_the_removed_tets(grasp_and_cut, scenes):
    sim, _, _ = grasp_and_cut
    whole = sinew.Simulation(sinew.load_scene_file(scenes / "grasp_and_cut.json"), backend="cpu")
    assert not np.array_equal(sim.surface_triangles(), whole.surface_triangles())


def test_frame_stats_are_attributes(grasp_and_cut, scenes):
    sim, _, stats = grasp_and_cut
    dt = sinew.load_scene_file(scenes / "grasp_and_cut.json").time_step
    assert [s.frame for s in stats] == list(range(1, 76))
    last = sim.last_frame
    assert last.frame == 75 and math.isclose(last.time, 75 * dt, rel_tol=1e-12)
    assert last.sweeps == 10 * 2  # substeps x iterations, fixed mode
    assert last.stop == "fixed"
    assert last.wall_ms > 0.0 and math.isfinite(last.residual_rms) and last.residual_rms > 0.0
    assert last.kinetic_energy > 0.0  # the cut strip still swings
    assert math.isfinite(last.volume_change) and abs(last.volume_change) < 0.05
    names = [s.name for s in last.stages]
    assert "solve" in names
    assert last.stage_ms("solve") == last.stages[names.index("solve")].ms
    for s in last.stages:
        for counter, value in s.counters.items():
            assert last.counter(s.name, counter) == value


def test_scene_info(grasp_and_cut):
    sim, _, _ = grasp_and_cut
    info = sim.info
    assert info.particles == 17 * 3 * 5 == sim.particles
    assert info.constraints == info.distance_constraints + info.volume_constraints + info.other_constraints
    assert info.tet_body_first_particle == [0]
    assert sim.backend_name == "cpu" and "CPU" in sim.device_name


def tool_scene(scenes, gravity):
    with open(scenes / "grasp_and_cut.json") as f:
        d = json.load(f)
    del d["script"], d["graspers"], d["colliders"]
    d["tools"] = [{"shape": "capsule", "radius": 0.004, "half_height": 0.01, "mass": 0.1,
                   "position": [0.06, 0.0145, 0.01], "rotation": [0.7071067811865476, 0.7071067811865476, 0.0, 0.0],
                   "gravity": gravity}]
    return sinew.scene_from_dict(d)


def test_tool_force_accelerates_it(scenes):
    sim = sinew.Simulation(tool_scene(scenes, gravity=False), backend="cpu")
    assert sim.tools.count == 1
    sim.tools.apply_force(0, [0.0, 0.2, 0.0])
    sim.step()
    state = sim.tools.state(0)
    dt = sim.last_frame.time
    assert math.isclose(state.velocity[1], 0.2 / 0.1 * dt, rel_tol=1e-9)
    assert state.contact_force == [0.0, 0.0, 0.0]  # lifted off, touching nothing
    with pytest.raises(sinew.Error, match="1"):
        sim.tools.state(1)


def test_tool_resting_on_tissue_feels_it(scenes):
    sim = sinew.Simulation(tool_scene(scenes, gravity=True), backend="cpu")
    pushed_up = []
    for _ in range(30):
        sim.step()
        pushed_up.append(sim.tools.state(0).contact_force[1])
    assert max(pushed_up) > 0.0


def test_needle_punctures_are_events(scenes):
    sim = sinew.Simulation(sinew.load_scene_file(scenes / "suturing.json"), backend="cpu")
    punctures = []
    for _ in range(30):
        sim.step()
        punctures.extend(e for e in sim.events if e.kind == "puncture")
    assert len(punctures) >= 2  # in, then out through the other side
    assert punctures[0].puncture.exit is False and any(e.puncture.exit for e in punctures)
    held = sim.needles.state(0).punctures
    for e in punctures:
        assert any(p.triangle == e.puncture.triangle and p.body == e.puncture.body for p in held)


def test_step_releases_the_gil(scenes):
    # While one thread steps, another runs Python: it sees the run part
    # done (with the GIL held it could only run after run() returned).
    sim = sinew.Simulation(sinew.load_scene_file(scenes / "tissue_sag.json"), backend="cpu")
    started = threading.Event()

    def work():
        started.set()
        sim.run(10)

    worker = threading.Thread(target=work)
    worker.start()
    started.wait()
    seen = sim.frame
    worker.join()
    assert seen < 10
    assert sim.frame == 10


def test_run_needs_a_frame(scenes):
    sim = sinew.Simulation(sinew.load_scene_file(scenes / "tissue_sag.json"), backend="cpu")
    with pytest.raises(sinew.Error) as raised:
        sim.run(0)
    assert raised.value.code == "bad_parameter" and "frames" in str(raised.value)
