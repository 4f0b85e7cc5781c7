#!/usr/bin/env bash
# The default job: builds the pose database from the CMU train split beside the repository
# (../shared/data/mocap/cmu31), or from CMU subjects fetched with tools/fetch_cmu.sh, prints
# what it holds and queries it with one of its own projections.
#
#   tools/demo.sh [--out FILE]     default FILE: build/db/cmu31_train.mdb
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mocap="$repo/build/bin/mocap"
out="$repo/build/db/cmu31_train.mdb"
while (( $# )); do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,7p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done

[[ -x "$mocap" ]] || { echo "demo.sh: $mocap is not built; run tools/setup.sh first" >&2; exit 1; }
shared="$repo/../shared/data/mocap/cmu31"
cache="${XDG_CACHE_HOME:-$HOME/.cache}/mocap/cmu"
if [[ -f "$shared/splits.txt" ]]; then
  inputs=("$shared" --split train)
elif compgen -G "$cache/*/*.amc" >/dev/null; then
  inputs=("$cache")
else
  echo "demo.sh: no motion capture found: expected $shared (the shared data beside the repository)" >&2
  echo "         or CMU subjects in $cache (download them with tools/fetch_cmu.sh 01 02 ... when online)" >&2
  exit 1
fi

mkdir -p "$(dirname "$out")"
"$mocap" db build "${inputs[@]}" --out "$out"
echo
"$mocap" db info "$out"
echo
echo "The database's projection 12345 searched for in the database itself (it must find itself first):"
"$mocap" db query "$out" --self 12345 --k 5
