# Shared by scripts/test and scripts/demo: install what is missing, build.
# Sourced, not run.

PVR_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
PVR_BUILD=${PVR_BUILD:-$PVR_ROOT/build}

# Debian packages the build, the tests and the demo need (README says why each).
PVR_PACKAGES=(
  build-essential cmake pkg-config
  libopenmpi-dev openmpi-bin
  tcl-dev tk-dev
  zlib1g-dev libssl-dev
  libopenimageio-dev openimageio-tools
  catch2 nlohmann-json3-dev libteem-dev libnifti2-dev
  clang libclang-rt-14-dev
  gnuplot-nox xvfb xauth
  iproute2 openssh-server munge slurm-wlm
)

# Only the demo: ffmpeg turns its frames into an MP4 and a GIF.
PVR_DEMO_PACKAGES=(ffmpeg)

# Installs what is missing of PVR_PACKAGES and the packages given.
pvr_install_missing() {
  local missing=()
  for p in "${PVR_PACKAGES[@]}" "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "installing: ${missing[*]}" >&2
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  # openssh-server, munge and slurm-wlm would start the machine's own
  # daemons on install; the tests start their own inside namespaces. A
  # policy-rc.d that refuses every start keeps them down (only while we install).
  local policy=/usr/sbin/policy-rc.d made_policy=""
  if [ ! -e "$policy" ]; then
    printf '#!/bin/sh\nexit 101\n' | $sudo tee "$policy" >/dev/null && $sudo chmod +x "$policy" && made_policy=1
  fi
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" || {
    [ -n "$made_policy" ] && $sudo rm -f "$policy"; return 1; }
  [ -n "$made_policy" ] && $sudo rm -f "$policy"
  return 0
}

# Open MPI refuses to run as root unless told; our jobs are local and ours.
pvr_mpi_env() {
  if [ "$(id -u)" -eq 0 ]; then
    export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  fi
  export OMPI_MCA_rmaps_base_oversubscribe=1
}

pvr_build() {
  cmake -S "$PVR_ROOT" -B "$PVR_BUILD" -DCMAKE_BUILD_TYPE=Release -DPVR_ASSERTIONS=ON "$@" >/dev/null
  cmake --build "$PVR_BUILD" -j"$(nproc)"
}
