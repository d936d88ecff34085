"""The README's ParaView picture: the last frame of a run written with `grains run --vtk`,
drawn as the README's steps say (open grains.pvd, Glyph with the radius array), with the
contact network as tubes coloured by normal force and the walls translucent.

usage: xvfb-run -a pvbatch docs/vtk/render.py RUN_DIR OUT.png
(ParaView 5.11, Debian's `paraview`; xvfb-run from `xvfb` where there is no display)
"""
import os
import sys

from paraview.simple import (  # noqa: E402
    ColorBy, GetActiveViewOrCreate, GetAnimationScene, GetColorTransferFunction, GetScalarBar, Glyph, OpenDataFile, Render, SaveScreenshot, Show, Tube,
)

run, png = sys.argv[1], sys.argv[2]
vtk = os.path.join(run, "vtk")
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [1200, 900]
view.Background = [1.0, 1.0, 1.0]
view.OrientationAxesVisibility = 0
try:
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass

grains = OpenDataFile(os.path.join(vtk, "grains.pvd"))
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
scene.AnimationTime = grains.TimestepValues[-1]

spheres = Glyph(Input=grains, GlyphType="Sphere")
spheres.ScaleArray = ["POINTS", "radius"]
spheres.ScaleFactor = 2.0  # the unit sphere's diameter is 1: scale by the diameter
spheres.GlyphMode = "All Points"
spheres.GlyphType.ThetaResolution = 24
spheres.GlyphType.PhiResolution = 16
shown = Show(spheres, view)
shown.Opacity = 0.35
ColorBy(shown, ("POINTS", "coordination"))
GetColorTransferFunction("coordination").ApplyPreset("Cool to Warm", True)

contacts = OpenDataFile(os.path.join(vtk, "contacts.pvd"))
chains = Tube(Input=contacts)
chains.Radius = 4.0e-5
chains.NumberofSides = 8
shown = Show(chains, view)
ColorBy(shown, ("CELLS", "normal_force"))
lut = GetColorTransferFunction("normal_force")
lut.ApplyPreset("Inferno (matplotlib)", True)
shown.SetScalarBarVisibility(view, True)
bar = GetScalarBar(lut, view)
bar.Title = "normal force (N)"
bar.ComponentTitle = ""
bar.TitleColor = bar.LabelColor = [0.1, 0.1, 0.1]

walls = OpenDataFile(os.path.join(vtk, "walls.pvd"))
shown = Show(walls, view)
shown.Opacity = 0.12
shown.DiffuseColor = [0.4, 0.4, 0.45]

# A side view from the front right, a little above: z up.
lo_x, hi_x, lo_y, hi_y, lo_z, hi_z = walls.GetDataInformation().GetBounds()
centre = [(lo_x + hi_x) / 2, (lo_y + hi_y) / 2, (lo_z + hi_z) / 4]
size = max(hi_x - lo_x, hi_y - lo_y)
view.CameraFocalPoint = centre
view.CameraPosition = [centre[0] + 1.5 * size, centre[1] - 2.2 * size, centre[2] + 1.3 * size]
view.CameraViewUp = [0.0, 0.0, 1.0]
view.CameraParallelProjection = 0
Render(view)
SaveScreenshot(png, view, ImageResolution=[1200, 900])
print(f"wrote {png}")
