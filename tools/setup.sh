#!/usr/bin/env bash
# Installs what the project needs from Debian's archive (apt-get, as root) and builds it in
# Release into build/. Idempotent: a second run with nothing to do only re-checks and rebuilds
# what changed.
#
#   tools/setup.sh              install packages, configure, build
#   tools/setup.sh --no-install skip the package step (you installed them yourself)
#   tools/setup.sh --help
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir="$repo/build"
install=1

for arg in "$@"; do
  case "$arg" in
    --no-install) install=0 ;;
    -h|--help)
      sed -n '2,8p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
      echo
      echo "Debian packages it installs:"
      "$0" --list-packages | tr '\n' ' ' | fold -s -w 96
      echo
      exit 0 ;;
    --list-packages) ;;
    *) echo "setup.sh: unknown option '$arg' (see --help)" >&2; exit 2 ;;
  esac
done

# What each package is for, so nobody wonders why it is here.
packages=(
  build-essential cmake ninja-build ccache pkg-config   # the toolchain
  libgtest-dev libgmock-dev libbenchmark-dev            # tests and benchmarks
  libglm-dev                                            # vectors and quaternions
  nlohmann-json3-dev zlib1g-dev                         # JSON files; CRC-32 of the database file
  libflann-dev liblz4-dev                               # FLANN nearest-neighbour search
  libfaiss-dev libblas-dev liblapack-dev                # FAISS search (measured against FLANN)
  libzmq3-dev cppzmq-dev libyaml-cpp-dev                # graph framework: ZeroMQ edges, YAML graphs
  python3 python3-zmq python3-numpy                     # wire-format client; NumPy cross-check of the npz reader
  libopencv-dev                                         # images and video: overlay, video sources
  blender                                               # a real BVH importer for the tests
  clang-format                                          # code style
)

if [[ " $* " == *" --list-packages "* ]]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi

if [[ -t 2 ]]; then
  log() { printf '\033[1m==> %s\033[0m\n' "$*" >&2; }
else
  log() { printf '==> %s\n' "$*" >&2; }
fi

if (( install )); then
  missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if (( ${#missing[@]} )); then
    sudo=""
    if (( EUID != 0 )); then
      command -v sudo >/dev/null || { echo "setup.sh: need root to install: ${missing[*]}" >&2; exit 1; }
      sudo="sudo"
    fi
    log "installing ${#missing[@]} Debian package(s): ${missing[*]}"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  else
    log "all ${#packages[@]} Debian packages already installed"
  fi
fi

jobs=$(nproc 2>/dev/null || echo 2)
if [[ ! -f "$build_dir/build.ninja" ]]; then
  log "configuring (Release) in $build_dir"
  cmake -S "$repo" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
log "building with $jobs job(s)"
cmake --build "$build_dir" --parallel "$jobs"
log "built $build_dir/bin/mocap"
