#!/usr/bin/env bash
# What the skeleton fit costs the default job: `mocap reconstruct VIDEO` end to end with --fit off
# and --fit full, run alternately (off, full, off, full, ...) so that both see the same load on a
# shared machine. Prints each run's wall time, the medians and their ratio (issue 17's target:
# full at most 1.25 x off), then the per-node table `mocap reconstruct` printed for the last run
# of each mode.
#
#   tools/bench/fit_cost.sh [--video FILE] [--runs N] [--db DB] [--out DIR] [-- EXTRA ARGS...]
#
# Defaults: OpenCV's vtest.avi (795 frames), 2 runs of each, build/db/cmu31_train.mdb, outputs in
# /tmp/mocap-bench-fit-cost. Extra arguments go to both runs (e.g. -- --detector-size 512).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

video=/usr/share/doc/opencv-doc/examples/data/vtest.avi
runs=2
db=build/db/cmu31_train.mdb
out=/tmp/mocap-bench-fit-cost
extra=()
while (($#)); do
  case "$1" in
    --video) video=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --db) db=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "fit_cost.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "fit_cost.sh: --runs wants a positive count" >&2; exit 2; }
for f in "$video" "$db" build/bin/mocap; do
  [[ -e "$f" ]] || { echo "fit_cost.sh: $f is absent (tools/setup.sh makes the binary and database)" >&2; exit 1; }
done
mkdir -p "$out"

median() { sort -g | awk '{v[NR]=$1} END {print (NR%2 ? v[(NR+1)/2] : (v[NR/2]+v[NR/2+1])/2)}'; }

declare -A times
echo "load: $(uptime | sed 's/.*load average/load average/')"
echo
echo "| run | fit | wall s | frames |"
echo "|---|---|---|---|"
for ((i = 1; i <= runs; ++i)); do
  for fit in off full; do
    dir="$out/$fit"
    t0=$(date +%s.%N)
    if ! build/bin/mocap reconstruct "$video" --db "$db" --out "$dir" --force --fit "$fit" \
      "${extra[@]}" >"$out/$fit.log" 2>&1; then
      echo "fit_cost.sh: the run with --fit $fit failed: $out/$fit.log" >&2
      tail -3 "$out/$fit.log" >&2
      exit 1
    fi
    t=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN {print b - a}')
    times[$fit]+="$t "
    frames=$(wc -l <"$dir/poses.jsonl")
    printf '| %d | %s | %.1f | %d |\n' "$i" "$fit" "$t" "$frames"
  done
done
off=$(tr ' ' '\n' <<<"${times[off]}" | grep . | median)
full=$(tr ' ' '\n' <<<"${times[full]}" | grep . | median)
echo
echo "| fit | median wall s | frames/s | vs off |"
echo "|---|---|---|---|"
frames=$(wc -l <"$out/off/poses.jsonl")
for fit in off full; do
  m=${!fit}
  awk -v f="$fit" -v m="$m" -v n="$frames" -v o="$off" \
    'BEGIN {printf "| %s | %.1f | %.1f | %.2f x |\n", f, m, n / m, m / o}'
done
for fit in off full; do
  echo
  echo "Per node, last run with --fit $fit:"
  echo
  echo '```'
  awk '/^node +type/{p = 1} p' "$out/$fit.log"
  echo '```'
done
