"""Particles as numpy arrays: copies into new or caller-given arrays,
surfaces as triangle index arrays, forces from numpy."""
import json

import numpy as np
import pytest

import sinew


@pytest.fixture()
def sag(scenes):
    sim = sinew.Simulation(sinew.load_scene_file(scenes / "tissue_sag.json"), backend="cpu")
    sim.run(2)
    return sim


def test_read_into_a_given_array(sag):
    out = np.full((sag.particles, 4), np.nan, dtype=np.float32)
    returned = sag.read_positions(out=out)
    assert returned is out
    assert out.tobytes() == sag.read_positions().tobytes()
    v = np.zeros((sag.particles, 4), dtype=np.float32)
    assert sag.read_velocities(out=v) is v
    assert np.any(v[:, :3] != 0.0)  # the block is falling
    # A copy, not a view: stepping does not change what was read.
    before = out.copy()
    sag.step()
    assert out.tobytes() == before.tobytes()
    assert sag.read_positions(out=out).tobytes() != before.tobytes()


@pytest.mark.parametrize("bad, what", [
    (lambda n: np.zeros((n, 4), dtype=np.float64), "float32"),
    (lambda n: np.zeros((n, 3), dtype=np.float32), "shape"),
    (lambda n: np.zeros((4, n), dtype=np.float32).T, "C-contiguous"),
    (lambda n: [[0.0] * 4] * n, "numpy array"),
])
def test_bad_out_array_is_refused(sag, bad, what):
    with pytest.raises(sinew.Error, match=what) as raised:
        sag.read_positions(out=bad(sag.particles))
    assert raised.value.code == "bad_parameter"


def test_read_only_out_array_is_refused(sag):
    out = np.zeros((sag.particles, 4), dtype=np.float32)
    out.flags.writeable = False
    with pytest.raises(sinew.Error, match="read-only"):
        sag.read_positions(out=out)


def test_surface_triangles_index_the_particles(sag):
    tris = sag.surface_triangles()
    assert tris.dtype == np.uint32 and tris.ndim == 2 and tris.shape[1] == 3
    # A closed boundary surface: every edge is shared by exactly two triangles.
    edges = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)
    assert tris.max() < sag.particles
    local = sag.surface_triangles(global_indices=False)
    assert np.array_equal(local + sag.info.tet_body_first_particle[0], tris)
    with pytest.raises(sinew.Error, match="tet body 3"):
        sag.surface_triangles(body=3)
    with pytest.raises(sinew.Error, match="kind"):
        sag.surface_triangles(kind="hex")


def forced_pair(scenes):
    with open(scenes / "tissue_sag.json") as f:
        d = json.load(f)
    d["external_forces"] = True
    scene = sinew.scene_from_dict(d)
    return sinew.Simulation(scene, backend="cpu"), sinew.Simulation(scene, backend="cpu")


def test_particle_forces_push_the_particles(scenes):
    pushed, free = forced_pair(scenes)
    forces = np.zeros((pushed.particles, 3), dtype=np.float32)
    tip = int(np.argmax(pushed.read_positions()[:, 0]))  # a particle of the free end
    forces[tip, 1] = 0.5  # up [N]
    pushed.set_particle_forces(forces)
    pushed.step()
    free.step()
    assert pushed.read_positions()[tip, 1] > free.read_positions()[tip, 1]


def test_bad_forces_are_refused(scenes):
    pushed, _ = forced_pair(scenes)
    with pytest.raises(sinew.Error, match="shape"):
        pushed.set_particle_forces(np.zeros((pushed.particles, 4), dtype=np.float32))
    nan = np.zeros((pushed.particles, 3), dtype=np.float32)
    nan[7, 2] = np.nan
    with pytest.raises(sinew.Error, match="7") as raised:
        pushed.set_particle_forces(nan)
    assert raised.value.code == "bad_parameter"


def test_forces_need_the_scene_to_allow_them(sag):
    with pytest.raises(sinew.Error, match="external_forces"):
        sag.set_particle_forces(np.zeros((sag.particles, 3), dtype=np.float32))
