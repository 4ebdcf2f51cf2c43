"""ParaView script: the particles of a joint run drawn as spheres, coloured by half, one PNG per
snapshot. The recipe of the README in code:

    xvfb-run -a pvpython python/paraview_joint.py out/joint          # out/joint/view_NNN.png
    xvfb-run -a pvpython python/paraview_joint.py out/joint displacement

Glyph mode All Points (the default samples only some points), sphere glyphs scaled by the
`radius` array times 2 (ParaView's sphere has diameter 1). The second argument is the array to
colour by (default `tag`: 1 lower half, 2 upper half).
"""

import os
import sys

from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetAnimationScene, Glyph, Hide,
                             ResetCamera, SaveScreenshot, Show, XDMFReader)

folder = sys.argv[1]
array = sys.argv[2] if len(sys.argv) > 2 else "tag"
reader = XDMFReader(FileNames=[os.path.join(folder, "joint.xdmf")])
reader.PointArrayStatus = ["id", "radius", "velocity", "group", "tag", "displacement", "force",
                           "angular_velocity"]
glyph = Glyph(Input=reader, GlyphType="Sphere")
glyph.ScaleArray = ["POINTS", "radius"]
glyph.ScaleFactor = 2.0
glyph.GlyphMode = "All Points"
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [1000, 800]
Hide(reader, view)
display = Show(glyph, view)
ColorBy(display, ("POINTS", array))
display.RescaleTransferFunctionToDataRange(True)
view.CameraPosition = [0.5, -2.0, 1.0]
view.CameraFocalPoint = [0.0, 0.0, 0.0]
view.CameraViewUp = [0.0, 0.0, 1.0]
ResetCamera(view)
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
times = list(reader.TimestepValues) if hasattr(reader.TimestepValues, "__len__") else [reader.TimestepValues]
for k, t in enumerate(times):
    scene.AnimationTime = t
    png = os.path.join(folder, f"view_{k:03d}.png")
    SaveScreenshot(png, view, ImageResolution=[1000, 800])
    print(f"{png}: shear displacement {t:g} mm, {reader.GetDataInformation().GetNumberOfPoints()} particles")
