#!/usr/bin/env python3
"""Colours as chosen: the CT head through one ParaView colour map, PVR beside VTK.

Two variants of one transfer function: "bone" (only bone from 600 HU,
opaque) and "haze" (the preset as it is: bone and a faint haze of soft
tissue, opacity 0.002 per voxel length).

Subcommands (run.sh calls them in this order):
  scene DIR     writes DIR/scene_bone.json and DIR/scene_haze.json for
                pvr-render: the CT head, the preset cool_to_warm_ct.json, a
                fixed perspective camera, 256x256, shading off (the colours
                are the transfer function's, not the lights'), black background
  vtk DIR       renders the same with VTK's vtkFixedPointVolumeRayCastMapper
                into DIR/vtk_bone.png and DIR/vtk_haze.png (needs an X
                display: run under xvfb-run -a)
  compare DIR   reads DIR/pvr_*.png and DIR/vtk_*.png, writes
                DIR/side_by_side.png (PVR left, VTK right; bone above, haze
                below) and DIR/regions.png (the same with the table's
                regions boxed in green), and prints the table

Both renderers get the same numbers: the preset's RGBPoints and opacity
Points, unit distance 1 voxel (0.957 mm), a step of half a voxel,
trilinear interpolation, the camera (eye, look-at, up, 30 degree vertical
field of view). VTK gets the preset's ColorSpace (Diverging), as ParaView
would apply it; PVR interpolates the RGB values (docs/scene.md, "ParaView
presets"), so the two agree at the preset's points and may differ between.
"""
import json
import math
import os
import struct
import sys
import zlib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
PRESET = os.path.join(HERE, "cool_to_warm_ct.json")
DATA = os.environ.get("PVR_SHARED_DATA", os.path.join(HERE, "..", "..", "..", "shared", "data"))
CT_JSON = os.path.abspath(os.path.join(DATA, "ct_head_cranium", "ct_head_cranium.json"))
SIZE = 256
FOV_Y_DEG = 30.0
AZIMUTH_DEG, ELEVATION_DEG = 30.0, 20.0

# Regions of the 256x256 image (x0, y0, x1, y1: columns and rows, row 0 at
# the top, end exclusive), chosen by looking at the images: what each holds
# is said in its label. The preset colour is the one expected there.
REGIONS = [
    ("bone", "opaque bone, face on", (104, 112, 152, 152), "bone"),
    ("bone", "opaque bone, top", (104, 92, 136, 100), "bone"),
    ("haze", "opaque bone, face on, behind the haze", (104, 112, 152, 152), "bone"),
    ("haze", "haze only, right of the skull", (174, 144, 182, 166), "tissue"),
    ("haze", "haze only, below the skull", (120, 200, 150, 210), "tissue"),
]
VARIANTS = ("bone", "haze")


def ct_meta():
    with open(CT_JSON) as f:
        return json.load(f)


def preset(variant="haze"):
    """The preset; for "bone", with the soft tissue's opacity set to 0."""
    with open(PRESET) as f:
        p = json.load(f)[0]
    if variant == "bone":
        pts = p["Points"]
        for i in range(0, len(pts), 4):
            if pts[i + 1] < 1:
                pts[i + 1] = 0.0
    return p


def camera():
    """Eye, look-at and up: the domain's centre seen from the -y side, turned
    30 degrees towards +x and raised 20 degrees, at the distance where the
    domain's bounding sphere (5 % larger) fills the field of view."""
    m = ct_meta()
    hi = [(n - 1) * s for n, s in zip(m["dims"], m["spacing"])]
    centre = [h / 2 for h in hi]
    radius = 1.05 * 0.5 * math.sqrt(sum(h * h for h in hi))
    dist = radius / math.sin(math.radians(FOV_Y_DEG / 2))
    az, el = math.radians(AZIMUTH_DEG), math.radians(ELEVATION_DEG)
    direction = [math.sin(az) * math.cos(el), -math.cos(az) * math.cos(el), math.sin(el)]
    eye = [c + dist * d for c, d in zip(centre, direction)]
    return eye, centre, [0.0, 0.0, 1.0]


def write_scene(out, variant):
    eye, look_at, up = camera()
    m = ct_meta()
    unit = min(m["spacing"])
    # The preset travels inline (the scene's "paraview" key), as read from the file.
    scene = {
        "volume": {"file": os.path.relpath(CT_JSON, os.path.abspath(out))},  # relative to the scene's folder
        "transfer_function": {"paraview": [preset(variant)], "unit_distance": unit},
        "camera": {"projection": "perspective", "eye": eye, "look_at": look_at, "up": up, "fov_y_deg": FOV_Y_DEG},
        "image": {"width": SIZE, "height": SIZE, "background": [0, 0, 0, 1]},
        "sampling": {"step": unit / 2},
        "shading": {"enabled": False},
    }
    with open(os.path.join(out, "scene_%s.json" % variant), "w") as f:
        json.dump(scene, f, indent=1)


def render_vtk(out, variant):
    from vtkmodules.vtkCommonCore import vtkVersion
    from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
    from vtkmodules.vtkIOImage import vtkImageReader2, vtkPNGWriter
    from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume,
                                             vtkVolumeProperty, vtkWindowToImageFilter)
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (object factory overrides)
    import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401  (the ray-cast image display helper)
    from vtkmodules.vtkRenderingVolume import vtkFixedPointVolumeRayCastMapper

    m = ct_meta()
    nx, ny, nz = m["dims"]
    reader = vtkImageReader2()
    reader.SetFileName(os.path.join(os.path.dirname(CT_JSON), m["raw_file"]))
    reader.SetFileDimensionality(3)
    reader.SetHeaderSize(0)
    reader.SetDataScalarTypeToShort()
    reader.SetDataByteOrderToLittleEndian()
    reader.SetNumberOfScalarComponents(1)
    reader.SetDataExtent(0, nx - 1, 0, ny - 1, 0, nz - 1)
    reader.SetDataSpacing(*m["spacing"])
    reader.SetDataOrigin(0, 0, 0)
    reader.FileLowerLeftOn()  # row 0 of a slice is y = 0, as PVR reads it

    p = preset(variant)
    ctf = vtkColorTransferFunction()
    ctf.SetColorSpaceToDiverging()  # the preset's ColorSpace, as ParaView applies it
    rgb = p["RGBPoints"]
    for i in range(0, len(rgb), 4):
        ctf.AddRGBPoint(*rgb[i:i + 4])
    otf = vtkPiecewiseFunction()
    pts = p["Points"]
    for i in range(0, len(pts), 4):
        otf.AddPoint(*pts[i:i + 4])
    unit = min(m["spacing"])
    prop = vtkVolumeProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetScalarOpacityUnitDistance(unit)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()

    mapper = vtkFixedPointVolumeRayCastMapper()
    mapper.SetSampleDistance(unit / 2)
    mapper.SetImageSampleDistance(1.0)  # one ray per pixel
    mapper.AutoAdjustSampleDistancesOff()
    mapper.LockSampleDistanceToInputSpacingOff()
    mapper.SetInputConnection(reader.GetOutputPort())
    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    ren = vtkRenderer()
    ren.SetBackground(0, 0, 0)
    ren.AddVolume(volume)
    win = vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(SIZE, SIZE)
    win.SetMultiSamples(0)
    win.AddRenderer(ren)
    eye, look_at, up = camera()
    cam = ren.GetActiveCamera()
    cam.SetPosition(*eye)
    cam.SetFocalPoint(*look_at)
    cam.SetViewUp(*up)
    cam.SetViewAngle(FOV_Y_DEG)  # vertical, as PVR's fov_y_deg
    ren.ResetCameraClippingRange()
    win.Render()

    grab = vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.ReadFrontBufferOff()
    grab.SetInputBufferTypeToRGB()
    grab.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(os.path.join(out, "vtk_%s.png" % variant))
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    print("%s: VTK %s %s, window %s" % (variant, vtkVersion.GetVTKVersion(), mapper.GetClassName(),
                                        win.GetClassName()))


def read_png(path):
    """RGB rows, row 0 at the top, as uint8."""
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    r = vtkPNGReader()
    r.SetFileName(path)
    r.Update()
    img = r.GetOutput()
    w, h, _ = img.GetDimensions()
    a = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)
    return a[::-1, :, :3].copy()  # VTK images start at the bottom row


def write_png(path, rgb):
    """An 8-bit RGB PNG of rows (row 0 at the top), filter 0 on every row."""
    h, w, _ = rgb.shape
    raw = b"".join(b"\0" + rgb[y].tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def preset_rgb_at(s):
    """The preset's colour at scalar s, interpolated in its RGB values (clamped)."""
    rgb = preset()["RGBPoints"]
    xs = rgb[0::4]
    return [float(np.interp(s, xs, rgb[1 + c::4])) for c in range(3)]


def srgb_to_linear(c):
    c = np.asarray(c, dtype=float)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def compare(out):
    images = {(r, v): read_png(os.path.join(out, "%s_%s.png" % (r, v))) for r in ("pvr", "vtk") for v in VARIANTS}
    gap = 4
    rows = []
    for v in VARIANTS:
        rows.append(np.concatenate([images["pvr", v], np.full((SIZE, gap, 3), 255, np.uint8), images["vtk", v]], axis=1))
        rows.append(np.full((gap, 2 * SIZE + gap, 3), 255, np.uint8))
    side = np.concatenate(rows[:-1], axis=0)
    # The table's boxes drawn on a copy (the figure keeps the renderers' pixels).
    boxed = side.copy()
    for variant, _, (x0, y0, x1, y1), _ in REGIONS:
        oy = VARIANTS.index(variant) * (SIZE + gap)
        for ox in (0, SIZE + gap):
            boxed[oy + y0, ox + x0:ox + x1] = boxed[oy + y1 - 1, ox + x0:ox + x1] = (0, 255, 0)
            boxed[oy + y0:oy + y1, ox + x0] = boxed[oy + y0:oy + y1, ox + x1 - 1] = (0, 255, 0)
    write_png(os.path.join(out, "side_by_side.png"), side)
    write_png(os.path.join(out, "regions.png"), boxed)

    bone = tuple(round(255 * c) for c in preset_rgb_at(600))
    tissue_hu = 30  # brain and skin, about 0..60 HU
    tissue = tuple(round(255 * c) for c in preset_rgb_at(tissue_hu))
    print("| transfer function | region (x0,y0)-(x1,y1) | PVR mean RGB | VTK mean RGB | preset colour there (sRGB 0-255) |")
    print("|---|---|---|---|---|")
    for variant, label, (x0, y0, x1, y1), kind in REGIONS:
        p = images["pvr", variant][y0:y1, x0:x1].reshape(-1, 3).mean(axis=0)
        v = images["vtk", variant][y0:y1, x0:x1].reshape(-1, 3).mean(axis=0)
        want = ("%d,%d,%d (the red end: every scalar from 600 HU)" % bone if kind == "bone" else
                "%d,%d,%d at %d HU, through a haze of opacity well below 1" % (tissue + (tissue_hu,)))
        print("| %s | %s (%d,%d)-(%d,%d) | %.1f, %.1f, %.1f | %.1f, %.1f, %.1f | %s |" %
              ((variant, label, x0, y0, x1, y1) + tuple(p) + tuple(v) + (want,)))
    # The haze: a layer of colour C and opacity A over black is A * C in
    # linear light for PVR (C decoded, multiplied, encoded again), A * C in
    # the display values themselves for VTK. The opacity each pixel implies:
    print()
    print("Opacity A that each renderer's haze-only pixels imply for the preset colour at %d HU"
          " (mean over R, G, B):" % tissue_hu)
    c = np.array(preset_rgb_at(tissue_hu))
    for variant, label, (x0, y0, x1, y1), kind in REGIONS:
        if kind != "tissue":
            continue
        p = images["pvr", variant][y0:y1, x0:x1].reshape(-1, 3).mean(axis=0) / 255
        v = images["vtk", variant][y0:y1, x0:x1].reshape(-1, 3).mean(axis=0) / 255
        print("  %s: PVR (A * C in linear light) A = %.3f; VTK (A * C in sRGB values) A = %.3f" %
              (label, float(np.mean(srgb_to_linear(p) / srgb_to_linear(c))), float(np.mean(v / c))))


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in ("scene", "vtk", "compare"):
        sys.exit(__doc__)
    out = sys.argv[2]
    os.makedirs(out, exist_ok=True)
    if sys.argv[1] == "compare":
        compare(out)
    else:
        for variant in VARIANTS:
            {"scene": write_scene, "vtk": render_vtk}[sys.argv[1]](out, variant)


if __name__ == "__main__":
    main()
