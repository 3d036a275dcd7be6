#!/usr/bin/env bash
# Speed against error, and the project's rendering targets.
#
# Installs what is missing, builds speed_vs_error and pvr-render (Release,
# assertions off) in build-bench/, writes the peer benchmark's volume to
# build/bench-data/, times the peer scene beside VTK's fixed-point ray caster
# on the peer's own camera path (the two by turns, three rounds) with both
# errors against one reference
# (VTK's frame at the scene's own view, bench/speed_vs_error/vtk_own_view.py)
# and, in the same rounds, the per-core sample rates of the peer scene and
# the CT head at their own settings (the targets take the rounds' median),
# runs the sweep (table on stdout,
# bench/results/speed_vs_error.csv), plots PSNR against time per frame
# (bench/results/speed_vs_error.png) and ends with the targets. Everything
# printed is also kept in bench/results/speed_vs_error.txt.
#
# Knobs: BENCH_BUILD (build dir, default build-bench), BENCH_ARGS (extra
# speed_vs_error options for the sweep, e.g. "--frames 3" or scene files),
# BENCH_CASE_SECONDS (3: stop timing a case after this long, at least one
# frame), BENCH_VTK_ROUNDS (3: rounds of VTK's run and ours by turns),
# BENCH_SKIP_INSTALL=1, BENCH_SKIP_VTK=1, BENCH_SOURCE (names the
# source tree in the results when it is not a git checkout).
set -euo pipefail

HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source "$HERE/../../scripts/lib/common.sh"
BUILD=${BENCH_BUILD:-$PVR_ROOT/build-bench}
RESULTS=$PVR_ROOT/bench/results
DATA=$PVR_ROOT/build/bench-data
PEERS=${PVR_PEERS_DIR:-$(dirname "$PVR_ROOT")/shared/peers}
PY=/usr/bin/python3  # Debian's python: numpy and VTK; not a pyenv python3 on the PATH
SVE=$BUILD/bench/speed_vs_error/speed_vs_error
PEER_SCENE=$PVR_ROOT/bench/scenes/peer_blobs.json
CT_SCENE=$PVR_ROOT/examples/scenes/ct_head_bone.json
STARTED=$(date +%s)

mkdir -p "$RESULTS"
exec > >(tee "$RESULTS/speed_vs_error.txt") 2>&1
log() { printf '[speed_vs_error %s] %s\n' "$(date +%H:%M:%S)" "$*"; }
# Figures from speed_vs_error --quick's output.
frame_seconds() { sed -n 's/.*time per frame *\([0-9.]*\) s.*/\1/p'; }
per_core_rate() { sed -n 's/.*samples per second .* \([0-9.]*\) M per core.*/\1/p'; }

# ---------------------------------------------------------------- packages
apt_install() {  # packages...; never removes anything (python3-vtk9 conflicts with python3-paraview)
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get -o DPkg::Lock::Timeout=600 update -qq &&
    DEBIAN_FRONTEND=noninteractive $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -qq \
      --no-install-recommends --no-remove "$@"
}
installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }

VTK_NOTE=""
if [ "${BENCH_SKIP_INSTALL:-0}" != 1 ]; then
  pvr_install_missing
  installed python3-numpy || apt_install python3-numpy
  if ! installed python3-vtk9; then
    log "installing python3-vtk9 for the VTK peer run"
    apt_install python3-vtk9 >/tmp/speed_vs_error_vtk_install.log 2>&1 ||
      VTK_NOTE="python3-vtk9 could not be installed ($(tail -1 /tmp/speed_vs_error_vtk_install.log))"
  fi
fi
if [ -z "$VTK_NOTE" ] && ! $PY -c "import vtkmodules.vtkRenderingVolume" 2>/dev/null; then
  VTK_NOTE="python3-vtk9 is not installed; VTK's time is not measured in this run"
fi

# ---------------------------------------------------------------- build
log "building speed_vs_error and pvr-render in $BUILD"
cmake -S "$PVR_ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DPVR_ASSERTIONS=OFF >/dev/null
cmake --build "$BUILD" --target speed_vs_error pvr-render -j2 | grep -E "error|warning|Built target" || true
[ -x "$SVE" ] || { log "build failed"; exit 1; }

# ---------------------------------------------------------------- peer volume
$PY "$PVR_ROOT/bench/scenes/peer_blobs.py" volume "$DATA"
if ! diff -q <($PY "$PVR_ROOT/bench/scenes/peer_blobs.py" scene) "$PEER_SCENE" >/dev/null; then
  log "WARNING: bench/scenes/peer_blobs.json differs from what peer_blobs.py derives from $PEERS/peer_common.py"
fi

SOURCE=$(git -C "$PVR_ROOT" describe --always --dirty 2>/dev/null || echo "${BENCH_SOURCE:-unknown}")
LOAD_BEFORE=$(cut -d' ' -f1-3 /proc/loadavg)
log "source $SOURCE; load average before: $LOAD_BEFORE ($(nproc) cores; other sessions share them)"

# ---------------------------------------------------------------- peer: ours beside VTK
# Both timed on the peer's camera path: 20 frames, +5 degrees azimuth each.
# The host's load moves both times by up to a third within minutes (VTK's
# more than ours), so the two run by turns, BENCH_VTK_ROUNDS rounds (3): a
# VTK run, then ours; each run's median is kept, and the ratio is the median
# of VTK's medians over the median of ours, beside each round's own ratio.
# Both errors against one reference, the scene's own view at the sweep's
# 256x256: VTK's warm-up frame at that view and size (vtk_own_view.py) and
# ours, each as 8-bit RGB over black (speed_vs_error --peer-png). VTK
# composites its colours as display values where PVR decodes them to linear
# light (docs/scene.md), so its frame is also compared with the reference of
# the scene as VTK models it (peer_blobs.py vtk-model, --peer-model).
ROUNDS=${BENCH_VTK_ROUNDS:-3}
source "$HERE/../lib/median.sh"  # median_of
VTK_MEDIANS=() OURS_MEDIANS=() PEER_RATES=() CT_RATES=()
VTK_PNG=$DATA/vtk_peer_own_view.png
rm -f "$VTK_PNG"
vtk_round() {  # round number -> VTK's median appended to VTK_MEDIANS, or VTK_NOTE set
  log "peer scene, VTK 9.1 vtkFixedPointVolumeRayCastMapper, 2 threads (xvfb-run), round $1 of $ROUNDS"
  local out
  if out=$(xvfb-run -a $PY "$PEERS/vtk_fixedpoint.py" --raw "$DATA/volume_256.raw" \
      --mapper fixedpoint --threads 2 -k 20 --png "$DATA/vtk_peer.png" 2>&1); then
    echo "$out" | tail -2
    VTK_MEDIANS+=("$(echo "$out" | sed -n 's/.*median \([0-9.]*\) s.*/\1/p')")
  else
    echo "$out" | tail -5
    VTK_NOTE="vtk_fixedpoint.py failed (output above)"
  fi
}
VTK_ROUNDS=0
if [ -z "$VTK_NOTE" ] && [ "${BENCH_SKIP_VTK:-0}" != 1 ]; then
  VTK_ROUNDS=$ROUNDS
  vtk_round 1
  log "peer scene, VTK's frame at the scene's own view, for its error"
  xvfb-run -a $PY "$HERE/vtk_own_view.py" "$PEERS" "$DATA/volume_256.raw" "$VTK_PNG" 256x256 2>&1 | tail -1 ||
    log "vtk_own_view.py failed: VTK's error is not measured"
  $PY "$PVR_ROOT/bench/scenes/peer_blobs.py" vtk-model "$DATA/peer_blobs_vtk_model.json"
elif [ "${BENCH_SKIP_VTK:-0}" = 1 ]; then
  VTK_NOTE="VTK run skipped (BENCH_SKIP_VTK=1)"
fi
[ -z "$VTK_NOTE" ] || log "$VTK_NOTE"
PEER_PNG_ARGS=()
[ -s "$VTK_PNG" ] && PEER_PNG_ARGS=(--peer-png "$VTK_PNG" --peer-model "$DATA/peer_blobs_vtk_model.json")
OURS_ROUNDS=$((VTK_ROUNDS > 0 ? VTK_ROUNDS : 1))  # without VTK, nothing to take turns with
for ((round = 1; round <= OURS_ROUNDS; round++)); do
  ((round == 1)) || [ -n "$VTK_NOTE" ] || vtk_round "$round"
  log "peer scene, our ray caster, 2 threads, the peer's camera path, round $round of $OURS_ROUNDS"
  OUT=$("$SVE" --quick "$PEER_SCENE" --orbit 20 --threads 2 "${PEER_PNG_ARGS[@]}" | tee /dev/stderr)
  OURS_MEDIANS+=("$(echo "$OUT" | frame_seconds)")
  ((round > 1)) || OURS_OUT=$OUT
  # The two per-core rate targets at the scenes' own settings and views,
  # in the same rounds: one sweep case each was a single measurement on a
  # shared host, and their verdicts moved by more than the margins.
  log "peer scene and CT head at their own settings, per-core rates, round $round of $OURS_ROUNDS"
  PEER_RATES+=("$("$SVE" --quick "$PEER_SCENE" --threads 2 --frames 20 | tee /dev/stderr | per_core_rate)")
  CT_RATES+=("$("$SVE" --quick "$CT_SCENE" --threads 2 --frames 20 | tee /dev/stderr | per_core_rate)")
done
VTK_MEDIAN=$(echo "${VTK_MEDIANS[*]}" | median_of)
OURS_ORBIT=$(echo "${OURS_MEDIANS[*]}" | median_of)
VTK_PSNR=$(echo "$OURS_OUT" | sed -n 's/.*peer frame error .*PSNR \([0-9.]*\) dB.*/\1/p')
OURS8_PSNR=$(echo "$OURS_OUT" | sed -n 's/.*our 8-bit error .*PSNR \([0-9.]*\) dB.*/\1/p')
OURS_PSNR=$(echo "$OURS_OUT" | sed -n 's/.*our RGB error .*PSNR \([0-9.]*\) dB.*/\1/p')
VTK_MODEL_PSNR=$(echo "$OURS_OUT" | sed -n 's/.*peer model error .*PSNR \([0-9.]*\) dB.*/\1/p')
# The same path at coarser steps: issue 13 asks for the speed "at no larger
# error" than VTK's, so each coarser setting is timed beside its own error.
COARSE=()  # "step seconds psnr8" per coarser step
for step in 1 2; do
  log "peer scene, our ray caster at step $step voxel, the peer's camera path"
  OUT=$("$SVE" --quick "$PEER_SCENE" --orbit 20 --threads 2 --step "$step" "${PEER_PNG_ARGS[@]:0:2}" | tee /dev/stderr)
  COARSE+=("$step $(echo "$OUT" | frame_seconds) \
$(echo "$OUT" | sed -n 's/.*our 8-bit error .*PSNR \([0-9.]*\) dB.*/\1/p')")
done

# ---------------------------------------------------------------- sweep
log "sweep: step x classification x skipping, every scene"
# shellcheck disable=SC2086  # BENCH_ARGS is a list of options
"$SVE" --threads 2 --frames 5 --case-seconds "${BENCH_CASE_SECONDS:-3}" \
  --csv "$RESULTS/speed_vs_error.csv" ${BENCH_ARGS:-}
LOAD_AFTER=$(cut -d' ' -f1-3 /proc/loadavg)
CSV=$RESULTS/speed_vs_error.csv
echo "# source $SOURCE; load average (1, 5, 15 min): before $LOAD_BEFORE, after $LOAD_AFTER; $(nproc) cores shared with other sessions" >>"$CSV"

# ---------------------------------------------------------------- plot
SCENES=$(awk -F, '!/^#/ && NR > 2 && !seen[$1]++ { printf "%s ", $1 }' "$CSV")
gnuplot -e "csv='$CSV'; out='$RESULTS/speed_vs_error.png'; scenes='$SCENES'; note='load average before $LOAD_BEFORE, after $LOAD_AFTER'" \
  "$HERE/plot.gp"
log "wrote $CSV and $RESULTS/speed_vs_error.png"

# ---------------------------------------------------------------- targets
# Columns: 1 scene, 3 shaded, 8 scene_default, 13 median_s, 18 msamples_per_s_per_core, 22 psnr_db
own() {  # scene column -> the value of that scene's own-settings row
  awk -F, -v s="$1" -v c="$2" '!/^#/ && $1 == s && $8 == 1 { print $c; exit }' "$CSV"
}
best() {  # shaded(0|1) -> the highest per-core rate of the sweep, and where
  awk -F, -v sh="$1" '!/^#/ && NR > 2 && $3 == sh && $18 > m { m = $18; w = $1 " step " $4 " voxel" (($6 == 1) ? " pre-integrated" : " plain") (($7 == 1) ? "" : " no skipping") }
    END { if (m) printf "%.1f M (%s)", m, w; else printf "n/a" }' "$CSV"
}
or_na() { [ -n "$1" ] && echo "$1" || echo "n/a"; }
echo
echo "=================================================================== targets"
echo "source $SOURCE; load average before $LOAD_BEFORE, after $LOAD_AFTER ($(nproc) cores shared; times are noisy)"
printf "%-64s %s\n" "peer scene s/frame, 2 threads, own view" "$(or_na "$(own peer_blobs 13)")"
printf "%-64s %s\n" "peer scene s/frame, 2 threads, peer camera path" "$(or_na "$OURS_ORBIT")"
if [ -n "$VTK_MEDIAN" ]; then
  printf "%-64s %s\n" "  VTK 9.1 fixed point, same path, this run" "$VTK_MEDIAN"
  awk -v o="$OURS_ORBIT" -v v="$VTK_MEDIAN" 'BEGIN { if (o > 0) printf "  %-62s %.2fx\n", "VTK time / ours (issue 13 target >= 5)", v / o }'
  for ((i = 0; i < ${#VTK_MEDIANS[@]} && i < ${#OURS_MEDIANS[@]}; i++)); do
    awk -v r=$((i + 1)) -v o="${OURS_MEDIANS[i]}" -v v="${VTK_MEDIANS[i]}" \
      'BEGIN { if (o > 0) printf "  %-62s %.2fx\n", sprintf("  round %d: VTK %.4f s, ours %.4f s", r, v, o), v / o }'
  done
else
  printf "  %-62s %s\n" "VTK 9.1 fixed point" "not measured: $VTK_NOTE"
fi
printf "  %-62s %s\n" "error at the own view, 8-bit RGB vs reference, PSNR dB: VTK" "$(or_na "$VTK_PSNR")"
printf "  %-62s %s\n" "  ours, rounded to 8 bits alike (target: >= VTK's)" "$(or_na "$OURS8_PSNR")"
printf "  %-62s %s\n" "  ours, float RGB" "$(or_na "$OURS_PSNR")"
printf "  %-62s %s\n" "  VTK against the reference of its own colour model" "$(or_na "$VTK_MODEL_PSNR")"
for row in "${COARSE[@]}"; do
  read -r step secs psnr8 <<<"$row"
  [ -n "$VTK_MEDIAN" ] && [ -n "$secs" ] || continue
  awk -v st="$step" -v o="$secs" -v v="$VTK_MEDIAN" -v p="${psnr8:-0}" -v vp="${VTK_PSNR:-999}" -v vm="${VTK_MODEL_PSNR:-999}" \
    'BEGIN { printf "  %-62s %.2fx\n", sprintf("at step %s voxel: %.4f s, 8-bit %.2f dB (%s VTK%s)", st, o, p,
             (p >= vp) ? ">=" : "<", (p >= vm) ? ", even on its own model" : ""), v / o }'
done
rates() {  # the rounds' rates -> "median (round 1, round 2, ...)"
  local m
  m=$(echo "$*" | median_of)
  [ -n "$m" ] && echo "$m (rounds: $*)" || echo "n/a"
}
printf "%-64s %s\n" "unshaded M samples/s per core, peer scene own (target 200)" "$(rates "${PEER_RATES[@]}")"
printf "%-64s %s\n" "  the sweep's case at the same settings" "$(or_na "$(own peer_blobs 18)")"
printf "%-64s %s\n" "  best unshaded case of the sweep" "$(best 0)"
printf "%-64s %s\n" "shaded M samples/s per core, CT head own (target 80)" "$(rates "${CT_RATES[@]}")"
printf "%-64s %s\n" "  the sweep's case at the same settings" "$(or_na "$(own ct_head_bone 18)")"
printf "%-64s %s\n" "  best shaded case of the sweep" "$(best 1)"
printf "%-64s %s\n" "CT head s/frame, 512x512, step 0.5 voxel, shaded (target < 0.15)" "$(or_na "$(own ct_head_bone 13)")"
echo "PSNR at each scene file's own settings, real volumes (target >= 45 dB):"
for s in ct_head_bone mri_head mri_brain_pd orbital_oxirane water_density; do
  printf "  %-62s %s\n" "$s" "$(or_na "$(own "$s" 22)")"
done
echo "(phantom default.json: $(or_na "$(own default 22)") dB; peer scene: $(or_na "$(own peer_blobs 22)") dB)"
log "done in $(( $(date +%s) - STARTED )) s"
