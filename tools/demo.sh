#!/usr/bin/env bash
# The default job: builds the pose database from the CMU train split beside the repository
# (../shared/data/mocap/cmu31; or CMU subjects fetched with tools/fetch_cmu.sh) when it is missing,
# then finds every pedestrian of OpenCV's vtest.avi (795 frames, 768x576, from Debian's opencv-doc)
# (mocap reconstruct's default detector, docs/detection-strategies.md), reconstructs their 3D
# motion and says where the results are.
#
#   tools/demo.sh [--out DIR] [--input VIDEO|FOLDER] [--detector NAME] [-- more reconstruct options]
#   defaults: out/, /usr/share/doc/opencv-doc/examples/data/vtest.avi, auto
#   a second demo replaces the first's output in DIR
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mocap="${MOCAP_BIN:-$repo/build/bin/mocap}"  # MOCAP_BIN: another build of it
db="$repo/build/db/cmu31_train.mdb"
out="$repo/out"
vtest=/usr/share/doc/opencv-doc/examples/data/vtest.avi
vtest_part="$repo/../shared/data/eval/opencv_samples/vtest_part0.avi"
input=""
detector=auto
extra=()
while (( $# )); do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --input) input="$2"; shift 2 ;;
    --detector) detector="$2"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) sed -n '2,10p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
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

if [[ -z "$input" ]]; then
  if [[ -f "$vtest" ]]; then
    input="$vtest"
  elif [[ -f "$vtest_part" ]]; then
    echo "demo.sh: $vtest is missing (Debian package opencv-doc: tools/setup.sh installs it);" >&2
    echo "         using its first 200 frames from the shared data instead: $vtest_part" >&2
    input="$vtest_part"
  else
    echo "demo.sh: no video to reconstruct: install opencv-doc (tools/setup.sh does) for $vtest," >&2
    echo "         or give one with --input VIDEO" >&2
    exit 1
  fi
fi
[[ -e "$input" ]] || { echo "demo.sh: no such input: $input" >&2; exit 1; }
echo "reconstructing $input (detector: $detector) into $out"
# --force: a demo run again replaces the output of the one before (reconstruct refuses a folder
# holding an earlier run's output otherwise); other files in the folder are left alone.
"$mocap" reconstruct "$input" --db "$db" --out "$out" --force --detector "$detector" --quiet \
  "${extra[@]}"
echo
echo "Open $out/overlay.mp4 to watch the video with every person's keypoints and id beside their 3D"
echo "skeletons; $out/person_<id>.bvh import into Blender, MotionBuilder or Maya; $out/poses.jsonl has"
echo "every frame's 15 joints per person; $out/summary.json the run's numbers."
