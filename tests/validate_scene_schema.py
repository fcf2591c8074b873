#!/usr/bin/env python3
"""Validates every scene file under scenes/ against scenes/schema/scene.schema.json,
and checks that the schema refuses what the reader refuses (an unknown key, a
negative density, an action of no known kind), so a schema that accepts
everything cannot pass.

    validate_scene_schema.py SCENES_DIR
"""
import copy
import json
import pathlib
import sys

import jsonschema

scenes = pathlib.Path(sys.argv[1])
schema = json.loads((scenes / "schema" / "scene.schema.json").read_text())
jsonschema.Draft202012Validator.check_schema(schema)
validator = jsonschema.Draft202012Validator(schema)

files = sorted(scenes.glob("*.json"))
if not files:
    sys.exit("no scene files under " + str(scenes))
failed = False
for path in files:
    errors = list(validator.iter_errors(json.loads(path.read_text())))
    for e in errors:
        print(f"{path.name}: /{'/'.join(str(p) for p in e.absolute_path)}: {e.message}")
    failed |= bool(errors)

base = json.loads((scenes / "tissue_sag.json").read_text())
bad = {
    "unknown key": lambda s: s["tet_bodies"][0].update({"densty": 1}),
    "negative density": lambda s: s["tet_bodies"][0].update({"density": -1}),
    # set_elastic refuses nu < 0.2 (a spring network cannot reach it).
    "elastic poisson_ratio below 0.2": lambda s: s["tet_bodies"][0]["elastic"].update({"poisson_ratio": 0.1}),
    "unknown action": lambda s: s.update({"script": {"actions": [{"frame": 1, "do": "explode"}]}}),
}
for what, spoil in bad.items():
    scene = copy.deepcopy(base)
    spoil(scene)
    if validator.is_valid(scene):
        print(f"the schema accepts a scene with {what}")
        failed = True
print(f"{len(files)} scene files checked against the schema")
sys.exit(1 if failed else 0)
