"""Scenes built from dicts: the same reader as the files, so a dict that
mirrors a file gives the same run, and a bad one the same errors, naming
the JSON path."""
import json
import math

import pytest

import sinew


def flagship_dict(scenes):
    with open(scenes / "tissue_sag.json") as f:
        return json.load(f)


def test_dict_runs_as_the_file_it_mirrors(scenes):
    from_file = sinew.Simulation(sinew.load_scene_file(scenes / "tissue_sag.json"), backend="cpu")
    from_dict = sinew.Simulation(sinew.scene_from_dict(flagship_dict(scenes), base_dir=scenes), backend="cpu")
    from_file.run(5)
    from_dict.run(5)
    assert from_dict.read_positions().tobytes() == from_file.read_positions().tobytes()
    assert from_dict.last_frame.residual_rms == from_file.last_frame.residual_rms


def test_scene_run_settings_are_read(scenes):
    scene = sinew.scene_from_dict(flagship_dict(scenes))
    assert scene.frames == 180 and scene.every == 10 and scene.backend == "auto"
    assert scene.bodies == [("tet", 0, "block")]


@pytest.mark.parametrize("path, value, code", [
    (("tet_bodies", 0, "elastic", "youngs_modulus"), -1.0, "bad_parameter"),
    (("solver", "substeps"), "twenty", "bad_input_file"),
    (("tet_bodies", 0, "density"), 0.0, "bad_parameter"),
])
def test_bad_value_names_its_json_path(scenes, path, value, code):
    d = flagship_dict(scenes)
    node = d
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(sinew.Error) as raised:
        sinew.scene_from_dict(d)
    assert raised.value.code == code
    assert "/" + "/".join(str(k) for k in path) in str(raised.value)


def test_unknown_key_is_named(scenes):
    d = flagship_dict(scenes)
    d["tet_bodies"][0]["densty"] = 1000.0
    with pytest.raises(sinew.Error, match="/tet_bodies/0/densty"):
        sinew.scene_from_dict(d)


def test_non_finite_value_is_refused(scenes):
    d = flagship_dict(scenes)
    d["gravity"][1] = math.nan
    with pytest.raises(sinew.Error, match="JSON") as raised:
        sinew.scene_from_dict(d)
    assert raised.value.code == "bad_input_file"


def test_error_is_a_runtime_error(scenes):
    with pytest.raises(RuntimeError):
        sinew.scene_from_dict({"tet_bodies": [{"density": 1000.0}]})


def test_missing_and_malformed_files_are_named(tmp_path):
    missing = tmp_path / "nowhere.json"
    with pytest.raises(sinew.Error, match="nowhere.json") as raised:
        sinew.load_scene_file(missing)
    assert raised.value.code == "bad_input_file"
    broken = tmp_path / "broken.json"
    broken.write_text('{"tet_bodies": [')
    with pytest.raises(sinew.Error, match="broken.json"):
        sinew.load_scene_file(broken)


def test_bad_backend_is_an_error(scenes):
    scene = sinew.load_scene_file(scenes / "tissue_sag.json")
    with pytest.raises(sinew.Error) as raised:
        sinew.Simulation(scene, backend="abacus")
    assert "abacus" in str(raised.value)
