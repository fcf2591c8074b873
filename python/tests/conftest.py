"""Shared fixtures of the Python tests: the module, the runner they compare
with (SINEW_RUNNER, set by ctest), the repository and a scratch folder."""
import os
import pathlib
import subprocess

import numpy as np
import pytest

import sinew

SOURCE_DIR = pathlib.Path(os.environ.get("SINEW_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture(scope="session")
def scenes():
    """The repository's scenes/ folder."""
    return SOURCE_DIR / "scenes"


@pytest.fixture(scope="session")
def runner_positions(tmp_path_factory):
    """run(scene, backend, frames): the runner's final positions, an N x 4
    float32 array read from `sinew run ... --positions FILE`."""
    runner = os.environ.get("SINEW_RUNNER")
    if not runner:
        pytest.fail("SINEW_RUNNER is not set (ctest sets it to the built `sinew` program)")
    folder = tmp_path_factory.mktemp("runner")

    def run(scene, backend, frames):
        out = folder / f"{pathlib.Path(scene).stem}_{backend}_{frames}.xyzw"
        subprocess.run([runner, "run", str(scene), "--backend", backend, "--frames", str(frames), "--quiet",
                        "--positions", str(out)], check=True, stdout=subprocess.DEVNULL)
        return np.fromfile(out, dtype=np.float32).reshape(-1, 4)

    return run


def make_simulation(scene, backend, **options):
    """A Simulation on `backend`, or the test skipped when this machine has
    no such backend (not built, or no device or driver)."""
    if backend not in sinew.built_backends():
        pytest.skip(f"backend {backend} is not built")
    try:
        return sinew.Simulation(scene, backend=backend, **options)
    except sinew.Error as e:
        if e.code == "backend_unavailable":
            pytest.skip(f"backend {backend} is unavailable here: {e}")
        raise
