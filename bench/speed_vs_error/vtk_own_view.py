#!/usr/bin/python3
"""VTK's frame of the peer scene at the scene's own view, for its error.

  vtk_own_view.py PEERS_DIR VOLUME.raw OUT.png [WIDTHxHEIGHT]

Runs the peer's vtk_fixedpoint.py (fixed-point mapper, 2 threads; at
WIDTHxHEIGHT, default the peer's 512x512: speed_vs_error's reference is
256x256, and the image size changes neither VTK's rays through a pixel's
centre nor its sampling along them) with no timed frame: its warm-up frame is at the start view (peer_common's
START_AZIMUTH and START_ELEVATION, which bench/scenes/peer_blobs.json's
camera is derived from), and --png saves it. The peer script's frame
statistics need at least one timed frame, so they are reported as none
here instead; the peer files themselves are not changed.
"""
import math
import os
import sys


def main():
    if len(sys.argv) not in (4, 5):
        sys.exit("usage: vtk_own_view.py PEERS_DIR VOLUME.raw OUT.png [WIDTHxHEIGHT]")
    peers, raw, png = sys.argv[1:4]
    sys.path.insert(0, os.path.abspath(peers))
    import peer_common
    if len(sys.argv) == 5:
        peer_common.IMAGE_SIZE = tuple(int(n) for n in sys.argv[4].split("x"))
    timed = peer_common.frame_stats

    def frame_stats(times):
        if times:
            return timed(times)
        return {"frames": 0, "median_s": math.nan, "min_s": math.nan, "max_s": math.nan, "mean_s": math.nan}

    peer_common.frame_stats = frame_stats
    import vtk_fixedpoint
    return vtk_fixedpoint.main(["--raw", raw, "--mapper", "fixedpoint", "--threads", "2", "-k", "0",
                                "--png", png])


if __name__ == "__main__":
    sys.exit(main())
