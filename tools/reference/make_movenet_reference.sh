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
source "$(dirname "${BASH_SOURCE[0]}")/tfjs_env.sh"

usage_unless_args 9 "$@"
require_model movenet-multipose
run_maker "$model_root/movenet-multipose" "$reference_images" "$@"
