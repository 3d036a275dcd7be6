#!/usr/bin/python3
"""VTK's frame of the peer scene at the scene's own view, for its error.

  vtk_own_view.py PEERS_DIR VOLUME.raw OUT.png

Runs the peer's vtk_fixedpoint.py (fixed-point mapper, 2 threads, 512x512)
with no timed frame: its warm-up frame is at the start view (peer_common's
START_AZIMUTH and START_ELEVATION, which bench/scenes/peer_blobs.json's
camera is derived from), and --png saves it. The peer script's frame
statistics need at least one timed frame, so they are reported as none
here instead; the peer files themselves are not changed.
"""
import math
import os
import sys


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: vtk_own_view.py PEERS_DIR VOLUME.raw OUT.png")
    peers, raw, png = sys.argv[1:]
    sys.path.insert(0, os.path.abspath(peers))
    import peer_common
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
