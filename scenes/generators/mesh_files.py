"""Mesh files as the generators read them: the same numbers, in the same
order, as sinew's readers make of them (Python's floats are the same IEEE
doubles)."""


def read_node(path):
    """A TetGen .node file's vertices, in the file's order and units."""
    with open(path) as f:
        rows = [line.split("#")[0].split() for line in f]
    rows = [r for r in rows if r]
    count = int(rows[0][0])
    return [[float(c) for c in r[1:4]] for r in rows[1:1 + count]]
