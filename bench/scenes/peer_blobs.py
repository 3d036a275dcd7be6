#!/usr/bin/python3
"""The peer benchmark's scene (../shared/peers) in PVR's own terms.

  peer_blobs.py volume OUTDIR   writes OUTDIR/volume_256.raw and its sidecar
                                with the peer's make_volume.py (needs numpy),
                                then PVR's sidecar OUTDIR/peer_blobs_256.json
  peer_blobs.py scene           prints the scene document (bench/scenes/peer_blobs.json)
  peer_blobs.py vtk-model OUT   writes the same scene as VTK composites it, for
                                VTK's error against its own model (see vtk_model)

The scene is derived from peer_common.py, so it is the peer's transfer
function and camera, not a copy typed by hand:

* Transfer function. VTK holds opacity and colour as two piecewise-linear
  functions with their own points; PVR holds one list of [scalar, r, g, b,
  opacity]. Evaluating both functions at the union of their positions gives
  points whose linear interpolation is exactly the same two functions.
* Camera. peer_common.camera_setup looks at the centre from -y at the
  distance where the half image height is half the box edge, with a 10 degree
  view angle; vtk_fixedpoint.py then calls Azimuth(30) and Elevation(20).
  VTK's Azimuth rotates the position about the view-up through the focal
  point; Elevation rotates it about cross(view plane normal, view-up), which
  is minus the camera's right vector, so a positive angle raises the eye and
  the view-up is kept. Both together put the eye at
  focal + d (cos el sin az, -cos el cos az, sin el), up +z.

Run with /usr/bin/python3 (Debian's numpy, for make_volume.py); the peer
directory is ../shared/peers beside the repository unless PVR_PEERS_DIR says
otherwise.
"""
import json
import math
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PEERS = os.environ.get("PVR_PEERS_DIR", os.path.join(os.path.dirname(ROOT), "shared", "peers"))
EDGE = 256
# Where bench/scenes/peer_blobs.json expects the volume, relative to bench/scenes.
VOLUME_FROM_SCENE = "../../build/bench-data/peer_blobs_%d.json" % EDGE

sys.path.insert(0, PEERS)
import peer_common as pc  # noqa: E402


def piecewise_linear(points, x):
    """Value of a VTK-style piecewise-linear function (clamped outside) at x.
    points: [(position, value...)] sorted by position."""
    if x <= points[0][0]:
        return list(points[0][1:])
    for (x0, *v0), (x1, *v1) in zip(points, points[1:]):
        if x <= x1:
            f = 0.0 if x1 == x0 else (x - x0) / (x1 - x0)
            return [a + f * (b - a) for a, b in zip(v0, v1)]
    return list(points[-1][1:])


def merged_points(meta):
    opacity, colour = pc.scaled_tf(meta)
    positions = sorted({p[0] for p in opacity} | {p[0] for p in colour})
    out = []
    for x in positions:
        r, g, b = piecewise_linear(colour, x)
        (a,) = piecewise_linear(opacity, x)
        # 15 significant digits: the double nearest the exact value, without
        # printing 0.1 * 0.3 as 0.030000000000000002.
        out.append([float("%.15g" % v) for v in (x, r, g, b, a)])
    return out


def camera(meta):
    focal, position, up, _half, view_angle = pc.camera_setup(meta)
    d = math.dist(focal, position)
    az, el = math.radians(pc.START_AZIMUTH), math.radians(pc.START_ELEVATION)
    towards_eye = (math.cos(el) * math.sin(az), -math.cos(el) * math.cos(az), math.sin(el))
    eye = [round(f + d * t, 9) for f, t in zip(focal, towards_eye)]
    return {"projection": "perspective", "eye": eye, "look_at": focal, "up": up,
            "fov_y_deg": view_angle}


def peer_meta():
    """The grid make_volume.py writes for uint8 (it records the same in its sidecar)."""
    return {"dims": [EDGE] * 3, "dtype": "uint8", "spacing": [1.0, 1.0, 1.0], "origin": [0.0, 0.0, 0.0]}


def scene():
    meta = peer_meta()
    w, h = pc.IMAGE_SIZE
    doc = {
        "volume": {"file": VOLUME_FROM_SCENE},
        "transfer_function": {"points": merged_points(meta),
                              "unit_distance": pc.SCALAR_OPACITY_UNIT_DISTANCE},
        "camera": camera(meta),
        "image": {"width": w, "height": h, "background": [0.0, 0.0, 0.0, 1.0]},
        "sampling": {"step": pc.SAMPLE_DISTANCE},
        "shading": {"enabled": False},
    }
    # Arrays of numbers on one line: one control point per line.
    text = json.dumps(doc, indent=2)
    text = re.sub(r"\[\s*([-+0-9.eE,\s]+?)\s*\]", lambda m: "[" + re.sub(r",\s*", ", ", m.group(1)) + "]", text)
    return text + "\n"


def srgb_encode(v):
    """Linear value to its sRGB encoding: the inverse of PVR's srgbToLinear
    (renderer/image_srgb.h), so PVR decodes it back to v."""
    return 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055


def vtk_model(out):
    """The peer scene as VTK renders it, in PVR's terms, written to OUT.

    PVR reads transfer-function colours as display sRGB and composites their
    linear decoding; VTK composites the numbers themselves. Here every colour
    is encoded, so PVR decodes it to VTK's number, at every integer scalar
    (PVR interpolates colours in encoded values between points: with points
    one scalar apart that bends the colour by ~1e-5). Opacity and everything
    else are the peer scene's. The volume is the one beside OUT."""
    meta = peer_meta()
    opacity, colour = pc.scaled_tf(meta)
    points = []
    for x in range(0, 256):
        r, g, b = (srgb_encode(v) for v in piecewise_linear(colour, float(x)))
        (a,) = piecewise_linear(opacity, float(x))
        points.append([float("%.15g" % v) for v in (float(x), r, g, b, a)])
    doc = json.loads(scene())
    doc["volume"]["file"] = "peer_blobs_%d.json" % EDGE
    doc["transfer_function"]["points"] = points
    with open(out, "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")
    print("wrote %s" % out)


def volume(outdir):
    os.makedirs(outdir, exist_ok=True)
    stem = os.path.join(outdir, "volume_%d" % EDGE)
    subprocess.run([sys.executable, os.path.join(PEERS, "make_volume.py"), "-n", str(EDGE), "-o", stem],
                   check=True)
    with open(stem + ".json") as fh:
        peer = json.load(fh)
    ours = {
        "dims": peer["dims"],
        "dtype": peer["dtype"],
        "spacing": peer["spacing"],
        "origin": peer["origin"],
        "raw_file": os.path.basename(stem) + ".raw",
        "endian": peer["byte_order"],
        "source": "../shared/peers/make_volume.py -n %d (sidecar %s.json, written by bench/scenes/peer_blobs.py)"
                  % (EDGE, os.path.basename(stem)),
    }
    path = os.path.join(outdir, "peer_blobs_%d.json" % EDGE)
    with open(path, "w") as fh:
        json.dump(ours, fh, indent=2)
        fh.write("\n")
    print("wrote %s" % path)


def main(argv):
    if len(argv) == 3 and argv[1] == "volume":
        volume(argv[2])
    elif len(argv) == 2 and argv[1] == "scene":
        sys.stdout.write(scene())
    elif len(argv) == 3 and argv[1] == "vtk-model":
        vtk_model(argv[2])
    else:
        sys.stderr.write("usage: peer_blobs.py volume OUTDIR | peer_blobs.py scene | peer_blobs.py vtk-model OUT\n")
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
