#!/usr/bin/env bash
# Remakes the MoveNet MultiPose golden reference with TensorFlow.js (pure-JS CPU backend, no
# native code), for tests/detect/movenet_golden_test.cpp. Installs @tensorflow/tfjs and pngjs
# with npm into a cache outside the repository on first use; takes about a minute.
#
#   tools/reference/make_movenet_reference.sh OUT.json [--check OLD.json]
#
# Inputs: the model from `tools/setup.sh --models-only`, the prepared PNGs in
# ../shared/docs/models/movenet-multipose/ (or $MOVENET_REFERENCE_IMAGES).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
cache="${XDG_CACHE_HOME:-$HOME/.cache}/mocap"
model_dir="${MOCAP_MODEL_DIR:-$cache/models}/movenet-multipose"
images="${MOVENET_REFERENCE_IMAGES:-$repo/../shared/docs/models/movenet-multipose}"
node_dir="$cache/reference-node"

if [[ $# -lt 1 || "$1" == -h || "$1" == --help ]]; then
  sed -n '2,9p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 2
fi
[[ -f "$model_dir/movenet-multipose.json" ]] || {
  echo "make_movenet_reference: no model in $model_dir; run tools/setup.sh --models-only" >&2
  exit 1
}
command -v node >/dev/null || { echo "make_movenet_reference: node (Node.js) is needed" >&2; exit 1; }
if [[ ! -d "$node_dir/node_modules/@tensorflow/tfjs" || ! -d "$node_dir/node_modules/pngjs" ]]; then
  echo "==> installing @tensorflow/tfjs@4.22.0 and pngjs@7.0.0 into $node_dir" >&2
  mkdir -p "$node_dir"
  npm install --prefix "$node_dir" --no-audit --no-fund --silent @tensorflow/tfjs@4.22.0 pngjs@7.0.0
fi
NODE_PATH="$node_dir/node_modules" exec node "$here/make_movenet_reference.js" "$model_dir" "$images" "$@"
