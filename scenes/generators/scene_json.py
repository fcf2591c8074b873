"""The generators' JSON layout: what fits a line on one line, the rest
indented (a key, a cut, a box each a line; floats as Python writes them,
the shortest text that reads back as the same double)."""
import json

WIDTH = 110


def dumps(value, indent=0):
    compact = json.dumps(value, separators=(", ", ": "))
    if len(compact) + indent <= WIDTH or not isinstance(value, (dict, list)) or not value:
        return compact
    pad = " " * (indent + 2)
    if isinstance(value, dict):
        items = [pad + json.dumps(k) + ": " + dumps(v, indent + 2) for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + " " * indent + "}"
    items = [pad + dumps(v, indent + 2) for v in value]
    return "[\n" + ",\n".join(items) + "\n" + " " * indent + "]"


def write(scene, out):
    out.write(dumps(scene) + "\n")
