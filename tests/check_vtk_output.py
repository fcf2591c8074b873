#!/usr/bin/env python3
"""The runner's binary VTK output read back by VTK itself (python3-vtk9).

  check_vtk_output.py readback RUNNER SCENES_DIR WORK
      a short tissue_sag run: VTK's reader gives the points of --positions
      bit for bit, the mesh's cells, displacement = points - frame 0's,
      alive 1 and strain 0 at rest; the .pvd lists frames 0, 1, 2 and each
      .vtm its blocks; grasp_and_cut's level-set collider is written too.
  check_vtk_output.py render RUNNER SCENES_DIR WORK RENDER_SCRIPT
      renders frame 2 of a short tissue_sag run offscreen; the PNG is not blank.
Exit 77 (ctest's skip) when VTK is not importable.
"""
import os
import shutil
import struct
import subprocess
import sys
import xml.etree.ElementTree as ET

try:
    import vtkmodules.all as vtk
except ImportError as e:
    print(f"SKIP: VTK for Python is not importable ({e}); install python3-vtk9")
    sys.exit(77)


def fail(msg):
    print(f"FAIL: {msg}")
    sys.exit(1)


def run(runner, scene, out, frames, every, positions=None):
    cmd = [runner, "run", scene, "--backend", "cpu", "--frames", str(frames), "--every", str(every), "--quiet",
           "--out", out]
    if positions:
        cmd += ["--positions", positions]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"{' '.join(cmd)} failed:\n{r.stdout}\n{r.stderr}")


def read_grid(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    if r.GetErrorCode() != 0:
        fail(f"VTK cannot read {path}")
    return r.GetOutput()


def tuples(array):
    n, c = array.GetNumberOfTuples(), array.GetNumberOfComponents()
    return [tuple(array.GetComponent(i, k) for k in range(c)) for i in range(n)]


def readback(runner, scenes, work):
    out = os.path.join(work, "sag")
    shutil.rmtree(out, ignore_errors=True)
    positions = os.path.join(work, "sag.bin")
    run(runner, os.path.join(scenes, "tissue_sag.json"), out, 2, 1, positions)
    raw = open(positions, "rb").read()
    xyzw = struct.unpack(f"<{len(raw) // 4}f", raw)
    g0, g2 = read_grid(os.path.join(out, "block_0.vtu")), read_grid(os.path.join(out, "block_2.vtu"))
    n = g2.GetNumberOfPoints()
    if n * 4 != len(xyzw):
        fail(f"block_2.vtu has {n} points, --positions {len(xyzw) // 4}")
    points = tuples(g2.GetPoints().GetData())
    expected = [tuple(xyzw[4 * i + k] for k in range(3)) for i in range(n)]
    # Both float32: equal as doubles means bit for bit.
    if points != expected:
        fail("block_2.vtu's points differ from --positions")
    cells = g2.GetNumberOfCells()
    if cells == 0 or any(g2.GetCellType(c) != 10 for c in range(cells)):
        fail("block_2.vtu's cells are not all tets")
    if g0.GetNumberOfCells() != cells:
        fail("frames 0 and 2 have different cell counts")
    for c in (0, cells - 1):
        a, b = g0.GetCell(c).GetPointIds(), g2.GetCell(c).GetPointIds()
        if [a.GetId(k) for k in range(4)] != [b.GetId(k) for k in range(4)]:
            fail(f"tet {c} has other points in frames 0 and 2")
    p0 = tuples(g0.GetPoints().GetData())
    disp = tuples(g2.GetPointData().GetArray("displacement"))
    for i in range(n):
        for k in range(3):
            if abs(disp[i][k] - (points[i][k] - p0[i][k])) > 1e-6:
                fail(f"point {i}: displacement {disp[i]} is not its move from frame 0")
    if max(abs(c) for t in tuples(g0.GetPointData().GetArray("displacement")) for c in t) > 1e-7:
        fail("frame 0's displacement is not zero")
    if max(abs(c) for t in disp for c in t) < 1e-6:
        fail("nothing moved in two frames of sagging")
    alive = tuples(g2.GetCellData().GetArray("alive"))
    if any(a != (1.0,) for a in alive):
        fail("a tet of a scene without cuts is not alive")
    strain0 = tuples(g0.GetCellData().GetArray("green_strain"))
    if max(s[0] for s in strain0) > 1e-5:
        fail(f"strain at rest is {max(s[0] for s in strain0)}")
    if max(s[0] for s in tuples(g2.GetCellData().GetArray("green_strain"))) <= 0.0:
        fail("no strain after two frames of sagging")
    if g2.GetPointData().GetArray("velocity") is None:
        fail("no velocity field")
    pvd = ET.parse(os.path.join(out, "scene.pvd")).getroot()
    files = [d.get("file") for d in pvd.iter("DataSet")]
    if files != ["scene_0.vtm", "scene_1.vtm", "scene_2.vtm"]:
        fail(f"scene.pvd lists {files}")
    mb = vtk.vtkXMLMultiBlockDataReader()
    mb.SetFileName(os.path.join(out, "scene_2.vtm"))
    mb.Update()
    blocks = mb.GetOutput()
    if blocks.GetNumberOfBlocks() != 1 or blocks.GetBlock(0).GetNumberOfPoints() != n:
        fail("scene_2.vtm does not hold the block")
    # A level-set collider (grasp_and_cut): its surface is a block.
    cut = os.path.join(work, "cut")
    shutil.rmtree(cut, ignore_errors=True)
    run(runner, os.path.join(scenes, "grasp_and_cut.json"), cut, 1, 1)
    collider = read_grid(os.path.join(cut, "collider0_1.vtu"))
    if collider.GetNumberOfCells() == 0 or collider.GetCellType(0) != 5:
        fail("grasp_and_cut's level-set collider has no triangles")
    print(f"PASS: {n} points, {cells} tets, fields and collections read back by VTK {vtk.vtkVersion.GetVTKVersion()}")


def render(runner, scenes, work, script):
    out = os.path.join(work, "render")
    shutil.rmtree(out, ignore_errors=True)
    run(runner, os.path.join(scenes, "tissue_sag.json"), out, 2, 1)
    png_dir = os.path.join(out, "png")
    r = subprocess.run([sys.executable, script, out, "--frames", "2", "--out-dir", png_dir, "--size", "320", "240"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"render_frames.py failed:\n{r.stdout}\n{r.stderr}")
    png = os.path.join(png_dir, "scene_2.png")
    reader = vtk.vtkPNGReader()
    reader.SetFileName(png)
    reader.Update()
    image = reader.GetOutput()
    w, h, _ = image.GetDimensions()
    if (w, h) != (320, 240):
        fail(f"{png} is {w} x {h}")
    scalars = image.GetPointData().GetScalars()
    colours = {tuple(int(scalars.GetComponent(i, k)) for k in range(3)) for i in range(0, w * h, 7)}
    if len(colours) < 10:
        fail(f"{png} is blank ({len(colours)} colours)")
    print(f"PASS: {png} has {len(colours)} colours")


if __name__ == "__main__":
    mode, runner, scenes, work = sys.argv[1:5]
    os.makedirs(work, exist_ok=True)
    if mode == "readback":
        readback(runner, scenes, work)
    elif mode == "render":
        render(runner, scenes, work, sys.argv[5])
    else:
        fail(f"unknown mode {mode}")
