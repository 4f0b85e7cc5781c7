# Sourced by the make_*_reference.sh scripts: where the models, the reference frame and the
# TensorFlow.js install live, and the checks and install they all do. Sets `here`, `repo`,
# `model_root`, `reference_images`; defines require_model, require_file and run_maker.
# shellcheck shell=bash

here=$(cd "$(dirname "${BASH_SOURCE[1]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
cache="${XDG_CACHE_HOME:-$HOME/.cache}/mocap"
model_root="${MOCAP_MODEL_DIR:-$cache/models}"
reference_images="${MOVENET_REFERENCE_IMAGES:-$repo/../shared/docs/models/movenet-multipose}"
node_dir="$cache/reference-node"
maker=$(basename "${BASH_SOURCE[1]}" .sh)

# The usage: the calling script's header comment, lines 2..N.
usage_unless_args() {
  local last_line=$1
  shift
  if [[ $# -lt 1 || "$1" == -h || "$1" == --help ]]; then
    sed -n "2,${last_line}p" "${BASH_SOURCE[1]}" | sed 's/^# \{0,1\}//'
    exit 2
  fi
}

require_model() {  # NAME [HINT]: NAME/NAME.json in the model cache
  [[ -f "$model_root/$1/$1.json" ]] || {
    echo "$maker: no model $1 in $model_root; ${2:-run tools/setup.sh --models-only}" >&2
    exit 1
  }
}

require_file() {
  [[ -f "$1" ]] || { echo "$maker: no file $1" >&2; exit 1; }
}

# Installs TensorFlow.js and pngjs into the cache on first use, then runs the maker's .js.
run_maker() {
  command -v node >/dev/null || { echo "$maker: node (Node.js) is needed" >&2; exit 1; }
  if [[ ! -d "$node_dir/node_modules/@tensorflow/tfjs" || ! -d "$node_dir/node_modules/pngjs" ]]; then
    echo "==> installing @tensorflow/tfjs@4.22.0 and pngjs@7.0.0 into $node_dir" >&2
    mkdir -p "$node_dir"
    npm install --prefix "$node_dir" --no-audit --no-fund --silent @tensorflow/tfjs@4.22.0 pngjs@7.0.0
  fi
  NODE_PATH="$node_dir/node_modules" exec node "$here/$maker.js" "$@"
}
