#!/usr/bin/env bash
# Colours as chosen (issue 14, point 4): the CT head through ParaView's
# "Cool to Warm", PVR beside VTK.
#
# Renders ../shared/data/ct_head_cranium with the preset cool_to_warm_ct.json
# (opacity, camera, image size, step and unit distance the same; shading
# off, so the colours are the transfer function's) in pvr-render and in
# VTK 9.1's vtkFixedPointVolumeRayCastMapper (Debian's python3-vtk9, under
# xvfb-run), twice: bone alone, and bone behind a faint haze of soft
# tissue. Writes the four PNGs, side_by_side.png (PVR left, VTK right; bone
# above, haze below), regions.png (the table's regions boxed) and
# table.md (mean colour of each region in both, and the preset's colour
# there) to bench/results/colours_vs_vtk/.
#
# Knobs: BENCH_BUILD (a build directory holding tools/pvr-render; default
# build), BENCH_SKIP_INSTALL=1, PVR_SHARED_DATA (default ../shared/data
# beside the checkout).
set -euo pipefail

HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source "$HERE/../../scripts/lib/common.sh"
BUILD=${BENCH_BUILD:-$PVR_ROOT/build}
RESULTS=$PVR_ROOT/bench/results/colours_vs_vtk
PY=/usr/bin/python3  # Debian's python: numpy and VTK; not a pyenv python3 on the PATH
RENDER=$BUILD/tools/pvr-render
log() { printf '[colours_vs_vtk %s] %s\n' "$(date +%H:%M:%S)" "$*" >&2; }

# ---------------------------------------------------------------- packages
installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
if [ "${BENCH_SKIP_INSTALL:-0}" != 1 ]; then
  missing=()
  for p in python3-vtk9 python3-numpy xvfb xauth; do installed "$p" || missing+=("$p"); done
  if [ ${#missing[@]} -gt 0 ]; then
    log "installing ${missing[*]}"
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    # --no-remove: python3-vtk9 conflicts with python3-paraview; never remove it silently.
    $sudo apt-get -o DPkg::Lock::Timeout=600 update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -qq \
      --no-install-recommends --no-remove "${missing[@]}"
  fi
fi

# ---------------------------------------------------------------- build
if [ ! -x "$RENDER" ]; then
  log "building pvr-render in $BUILD"
  cmake -S "$PVR_ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$BUILD" --target pvr-render -j2 >/dev/null
fi

# ---------------------------------------------------------------- render
mkdir -p "$RESULTS"
$PY "$HERE/compare.py" scene "$RESULTS"
for v in bone haze; do
  log "PVR, $v"
  "$RENDER" "$RESULTS/scene_$v.json" -o "$RESULTS/pvr_$v.png" >&2
done
log "VTK (xvfb-run)"
xvfb-run -a $PY "$HERE/compare.py" vtk "$RESULTS" >&2

# ---------------------------------------------------------------- compare
SOURCE=$(git -C "$PVR_ROOT" describe --always --dirty 2>/dev/null || echo unknown)
{
  echo "CT head (ct_head_cranium), ParaView 'Cool to Warm' rescaled to -600..600 HU, 256x256, shading off;"
  echo "PVR $SOURCE (pvr-render), $(xvfb-run -a $PY -c 'import vtk; print("VTK", vtk.vtkVersion.GetVTKVersion())') vtkFixedPointVolumeRayCastMapper; $(date -u +%Y-%m-%d)."
  echo
  $PY "$HERE/compare.py" compare "$RESULTS"
} | tee "$RESULTS/table.md"
log "written: $RESULTS/side_by_side.png, regions.png, table.md"
