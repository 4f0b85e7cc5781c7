#!/usr/bin/env bash
# The default job: builds the pose database from the CMU train split beside the repository
# (../shared/data/mocap/cmu31; or CMU subjects fetched with tools/fetch_cmu.sh), then reconstructs
# the 3D motion of every player in OpenPose's 750-frame badminton keypoints
# (../shared/data/eval/openpose_json) and says where the results are.
#
#   tools/demo.sh [--out DIR] [--input FOLDER]   defaults: out/, the badminton keypoints
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mocap="$repo/build/bin/mocap"
db="$repo/build/db/cmu31_train.mdb"
out="$repo/out"
input="$repo/../shared/data/eval/openpose_json/json"
while (( $# )); do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --input) input="$2"; shift 2 ;;
    -h|--help) sed -n '2,8p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done

[[ -x "$mocap" ]] || { echo "demo.sh: $mocap is not built; run tools/setup.sh first" >&2; exit 1; }
shared="$repo/../shared/data/mocap/cmu31"
cache="${XDG_CACHE_HOME:-$HOME/.cache}/mocap/cmu"
if [[ ! -f "$db" ]]; then
  if [[ -f "$shared/splits.txt" ]]; then
    inputs=("$shared" --split train)
  elif compgen -G "$cache/*/*.amc" >/dev/null; then
    inputs=("$cache")
  else
    echo "demo.sh: no motion capture found: expected $shared (the shared data beside the repository)" >&2
    echo "         or CMU subjects in $cache (download them with tools/fetch_cmu.sh 01 02 ... when online)" >&2
    exit 1
  fi
  mkdir -p "$(dirname "$db")"
  "$mocap" db build "${inputs[@]}" --out "$db"
fi
"$mocap" db info "$db"
echo
if [[ ! -d "$input" ]]; then
  echo "demo.sh: no keypoints to reconstruct at $input (give a folder of OpenPose JSON with --input)" >&2
  exit 1
fi
# The badminton keypoints come from a 1920x1080, 25 fps video (../shared/data/eval/openpose_json/README.md).
"$mocap" reconstruct "$input" --db "$db" --out "$out" --fps 25 --image-size 1920x1080 --quiet
echo
echo "Open $out/overlay.mp4 to watch the input beside the 3D result; $out/person_<id>.bvh import into"
echo "Blender, MotionBuilder or Maya; $out/poses.jsonl has every frame's 15 joints per person."
