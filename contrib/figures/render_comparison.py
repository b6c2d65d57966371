#!/usr/bin/python3
"""Renders a file comparison-NNNNN.vtu of the `fem comparison` postprocessor as two
pictures side by side: the springs' deformed surface and FEM's, each coloured by its
displacement magnitude on one colour scale (doc/accuracy.md).

    /usr/bin/python3 contrib/figures/render_comparison.py comparison-00002.vtu out.png \
        "title" [warp factor, default 1]

Needs Debian's python3-vtk9 and an X display (run it under xvfb-run -a).
"""
import sys

import vtk


def surface(grid, array):
    """The boundary of grid moved by the point array, with its magnitude as scalars."""
    grid.GetPointData().SetActiveVectors(array)
    outer = vtk.vtkDataSetSurfaceFilter()
    outer.SetInputData(grid)
    warp = vtk.vtkWarpVector()
    warp.SetInputConnection(outer.GetOutputPort())
    warp.SetScaleFactor(WARP)
    norm = vtk.vtkVectorNorm()
    norm.SetInputConnection(warp.GetOutputPort())
    # Flat faces, each lit by its own outward normal.
    normals = vtk.vtkPolyDataNormals()
    normals.SetInputConnection(norm.GetOutputPort())
    normals.SplittingOn()
    normals.SetFeatureAngle(10)
    normals.AutoOrientNormalsOn()
    normals.Update()
    return normals.GetOutput()


def label(text, size):
    """Black text at the lower left of its renderer."""
    actor = vtk.vtkTextActor()
    actor.SetInput(text)
    actor.GetTextProperty().SetColor(0, 0, 0)
    actor.GetTextProperty().SetFontSize(size)
    actor.SetPosition(12, 12)
    return actor


def panel(poly, lut, low, high, title, viewport, camera):
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(poly)
    mapper.SetLookupTable(lut)
    mapper.SetScalarRange(low, high)
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().EdgeVisibilityOn()
    actor.GetProperty().SetEdgeColor(0.2, 0.2, 0.2)
    actor.GetProperty().SetAmbient(0.35)
    actor.GetProperty().SetDiffuse(0.65)
    renderer = vtk.vtkRenderer()
    renderer.SetViewport(*viewport)
    renderer.SetBackground(1, 1, 1)
    renderer.AddActor(actor)
    renderer.AddActor2D(label(title, 20))
    renderer.SetActiveCamera(camera)
    return renderer


def main():
    global WARP
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    source, target, title = sys.argv[1:4]
    WARP = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(source)
    reader.Update()
    grid = reader.GetOutput()
    if grid.GetNumberOfPoints() == 0:
        sys.exit("Error: '%s' holds no mesh." % source)
    pieces = []
    for array in ("springs_displacement", "fem_displacement"):
        if grid.GetPointData().GetArray(array) is None:
            sys.exit("Error: '%s' has no point array '%s'." % (source, array))
        copy = vtk.vtkUnstructuredGrid()
        copy.DeepCopy(grid)
        pieces.append(surface(copy, array))
    high = max(p.GetPointData().GetScalars().GetRange()[1] for p in pieces)

    lut = vtk.vtkLookupTable()
    lut.SetHueRange(0.667, 0.0)
    lut.SetTableRange(0, high)
    lut.Build()

    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetMultiSamples(0)
    window.SetSize(1400, 560)
    camera = vtk.vtkCamera()
    names = ("springs (Section 3 of the paper)", "FEM P2 (Newmark)")
    renderers = []
    for k, (poly, name) in enumerate(zip(pieces, names)):
        renderer = panel(poly, lut, 0, high, name, (0.5 * k, 0, 0.5 * k + 0.5, 0.9),
                         camera)
        window.AddRenderer(renderer)
        renderers.append(renderer)
    banner = vtk.vtkRenderer()
    banner.SetViewport(0, 0.9, 1, 1)
    banner.SetBackground(1, 1, 1)
    banner.AddActor2D(label(title, 22))
    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(lut)
    bar.SetTitle("|u| (m)")
    bar.SetOrientationToHorizontal()
    bar.SetPosition(0.55, 0.05)
    bar.SetWidth(0.4)
    bar.SetHeight(0.9)
    bar.GetTitleTextProperty().SetColor(0, 0, 0)
    bar.GetLabelTextProperty().SetColor(0, 0, 0)
    bar.SetNumberOfLabels(5)
    banner.AddActor2D(bar)
    window.AddRenderer(banner)

    camera.SetFocalPoint(*grid.GetCenter())
    bounds = grid.GetBounds()
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4])
    centre = grid.GetCenter()
    camera.SetPosition(centre[0] + 0.9 * size, centre[1] - 1.4 * size,
                       centre[2] + 1.1 * size)
    camera.SetViewUp(0, 0, 1)
    renderers[0].ResetCamera()
    camera.Zoom(1.3)
    window.Render()
    image = vtk.vtkWindowToImageFilter()
    image.SetInput(window)
    image.Update()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(target)
    writer.SetInputConnection(image.GetOutputPort())
    writer.Write()
    print("Wrote %s (largest displacement %.4g m)" % (target, high))


if __name__ == "__main__":
    main()
