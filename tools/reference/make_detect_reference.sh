#!/usr/bin/env bash
# Remakes the golden reference of the single-pose MoveNet (Lightning, Thunder) and MB3-CenterNet
# ports (tests/detect/singlepose_golden_test.cpp, centernet_golden_test.cpp) with TensorFlow.js
# (pure-JS CPU backend, no native code). Installs @tensorflow/tfjs and pngjs with npm into a cache
# outside the repository on first use; takes about a minute.
#
#   tools/reference/make_detect_reference.sh OUT.json [--check OLD.json]
#
# Inputs: the models from `tools/setup.sh --models-only`, the frame
# ../shared/docs/models/movenet-multipose/vtest-f300.png (or $MOVENET_REFERENCE_IMAGES/...).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/tfjs_env.sh"

usage_unless_args 10 "$@"
for m in movenet-lightning movenet-thunder centernet; do require_model "$m"; done
frame="$reference_images/vtest-f300.png"
require_file "$frame"
run_maker "$model_root" "$frame" "$@"
