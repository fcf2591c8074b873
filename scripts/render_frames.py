#!/usr/bin/env python3
"""Renders frames of sinew's VTK output (a folder, its .pvd, or one .vtm/.vtu)
to PNG offscreen with VTK (Debian python3-vtk9): bodies coloured by a point
or cell field, tools, colliders and needles in grey.

  scripts/render_frames.py OUT_DIR --frames 0 60 --field displacement --out-dir pictures
  scripts/render_frames.py OUT_DIR/tissue_sag.pvd --last

Blocks whose name starts with "collider", "tool" or "needle", or that
carry no chosen field, are drawn grey; vector fields are coloured by their
magnitude. The camera looks at everything from the chosen --view. Debian's VTK renders
through X: without a DISPLAY the script runs itself under xvfb-run (Debian
xvfb) when it is there.
"""
import argparse
import os
import sys
import xml.etree.ElementTree as ET


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("source", help="an output folder (its .pvd), a .pvd, a .vtm or a .vtu")
    p.add_argument("--frames", type=int, nargs="*", default=None,
                   help="frame numbers (the N of NAME_N.vtm) to render; default: every frame")
    p.add_argument("--last", action="store_true", help="render the last frame only")
    p.add_argument("--field", default="displacement",
                   help="point or cell field colouring the bodies (default: displacement)")
    p.add_argument("--out-dir", default=None, help="folder for the PNGs (default: the source's folder)")
    p.add_argument("--size", type=int, nargs=2, default=[800, 600], metavar=("W", "H"), help="image size in pixels")
    p.add_argument("--view", choices=["front", "top", "side", "iso"], default="iso", help="camera direction")
    return p.parse_args()


def frames_of(source):
    """[(frame number, time, file)] of the source."""
    if os.path.isdir(source):
        pvds = sorted(f for f in os.listdir(source) if f.endswith(".pvd"))
        if not pvds:
            sys.exit(f"render_frames: no .pvd in {source}")
        source = os.path.join(source, pvds[0])
    if source.endswith(".pvd"):
        folder = os.path.dirname(source)
        out = []
        for i, d in enumerate(ET.parse(source).getroot().iter("DataSet")):
            f = os.path.join(folder, d.get("file"))
            stem = os.path.splitext(os.path.basename(f))[0]
            n = stem.rsplit("_", 1)[-1]
            out.append((int(n) if n.isdigit() else i, float(d.get("timestep", "0")), f))
        return out
    if source.endswith(".vtm") or source.endswith(".vtu"):
        return [(0, 0.0, source)]
    sys.exit(f"render_frames: {source} is not a folder, .pvd, .vtm or .vtu")


def blocks_of(vtk, path):
    """[(name, vtkUnstructuredGrid)] of a .vtm or .vtu file."""
    if path.endswith(".vtu"):
        r = vtk.vtkXMLUnstructuredGridReader()
        r.SetFileName(path)
        r.Update()
        return [(os.path.basename(path), r.GetOutput())]
    r = vtk.vtkXMLMultiBlockDataReader()
    r.SetFileName(path)
    r.Update()
    mb = r.GetOutput()
    out = []
    for i in range(mb.GetNumberOfBlocks()):
        name = mb.GetMetaData(i).Get(vtk.vtkCompositeDataSet.NAME()) if mb.HasMetaData(i) else str(i)
        if mb.GetBlock(i) is not None:
            out.append((name, mb.GetBlock(i)))
    return out


def render(vtk, blocks, field, size, view, png, title):
    renderer = vtk.vtkRenderer()
    renderer.SetBackground(1.0, 1.0, 1.0)
    lut = vtk.vtkLookupTable()
    lut.SetHueRange(0.667, 0.0)
    lut.Build()
    coloured = []
    for name, grid in blocks:
        if grid.GetNumberOfPoints() == 0:
            continue
        surface = vtk.vtkDataSetSurfaceFilter()
        surface.SetInputData(grid)
        mapper = vtk.vtkPolyDataMapper()
        mapper.SetInputConnection(surface.GetOutputPort())
        actor = vtk.vtkActor()
        actor.SetMapper(mapper)
        tool = name.startswith(("collider", "tool", "needle"))
        data = None if tool else (grid.GetPointData().GetArray(field) or grid.GetCellData().GetArray(field))
        if data is not None:
            point = grid.GetPointData().GetArray(field) is not None
            if point:
                mapper.SetScalarModeToUsePointFieldData()
            else:
                mapper.SetScalarModeToUseCellFieldData()
            mapper.SelectColorArray(field)
            mapper.SetLookupTable(lut)
            if data.GetNumberOfComponents() > 1:
                lut.SetVectorModeToMagnitude()
            mapper.ScalarVisibilityOn()
            coloured.append((mapper, data))
        else:
            mapper.ScalarVisibilityOff()
            actor.GetProperty().SetColor(0.6, 0.6, 0.6)
            if name.startswith("collider"):
                actor.GetProperty().SetOpacity(0.5)
        if grid.GetNumberOfCells() and grid.GetCellType(0) in (1, 3, 4):  # points and lines: visible sizes
            actor.GetProperty().SetPointSize(4)
            actor.GetProperty().SetLineWidth(3)
        renderer.AddActor(actor)
    if coloured:
        lo = min(d.GetRange(-1)[0] if d.GetNumberOfComponents() > 1 else d.GetRange()[0] for _, d in coloured)
        hi = max(d.GetRange(-1)[1] if d.GetNumberOfComponents() > 1 else d.GetRange()[1] for _, d in coloured)
        if hi <= lo:
            hi = lo + 1e-12
        for mapper, _ in coloured:
            mapper.SetScalarRange(lo, hi)
        bar = vtk.vtkScalarBarActor()
        bar.SetLookupTable(lut)
        bar.SetTitle(field)
        bar.SetNumberOfLabels(4)
        bar.GetTitleTextProperty().SetColor(0, 0, 0)
        bar.GetLabelTextProperty().SetColor(0, 0, 0)
        lut.SetRange(lo, hi)
        renderer.AddActor2D(bar)
    text = vtk.vtkTextActor()
    text.SetInput(title)
    text.GetTextProperty().SetColor(0, 0, 0)
    text.GetTextProperty().SetFontSize(18)
    renderer.AddActor2D(text)
    camera = renderer.GetActiveCamera()
    direction = {"front": (0, 0, 1), "top": (0, 1, 0), "side": (1, 0, 0), "iso": (1, 0.8, 1.2)}[view]
    camera.SetPosition(*direction)
    camera.SetFocalPoint(0, 0, 0)
    camera.SetViewUp(*((0, 0, -1) if view == "top" else (0, 1, 0)))
    renderer.ResetCamera()
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(*size)
    window.AddRenderer(renderer)
    window.Render()
    shot = vtk.vtkWindowToImageFilter()
    shot.SetInput(window)
    shot.Update()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(png)
    writer.SetInputConnection(shot.GetOutputPort())
    writer.Write()


def main():
    args = parse_args()
    if not os.environ.get("DISPLAY") and not os.environ.get("SINEW_RENDER_XVFB"):
        import shutil
        if shutil.which("xvfb-run"):
            env = dict(os.environ, SINEW_RENDER_XVFB="1")
            os.execvpe("xvfb-run", ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", sys.executable] + sys.argv, env)
    try:
        import vtkmodules.all as vtk
    except ImportError as e:
        sys.exit(f"render_frames: VTK for Python is not importable ({e}); install python3-vtk9")
    frames = frames_of(args.source)
    if args.last:
        frames = frames[-1:]
    elif args.frames is not None:
        wanted = set(args.frames)
        missing = wanted - {n for n, _, _ in frames}
        if missing:
            sys.exit(f"render_frames: no frame {sorted(missing)} in {args.source} "
                     f"(it has {[n for n, _, _ in frames]})")
        frames = [f for f in frames if f[0] in wanted]
    out_dir = args.out_dir or (args.source if os.path.isdir(args.source) else os.path.dirname(args.source) or ".")
    os.makedirs(out_dir, exist_ok=True)
    for n, t, path in frames:
        png = os.path.join(out_dir, f"{os.path.splitext(os.path.basename(path))[0]}.png")
        render(vtk, blocks_of(vtk, path), args.field, args.size, args.view, png, f"frame {n}  t = {t:.3f} s")
        print(f"wrote {png}")


if __name__ == "__main__":
    main()
