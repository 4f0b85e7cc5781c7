#!/usr/bin/env bash
# Runs one libFuzzer target of tests/fuzz (docs/fuzzing.md) for a while.
#
#   tools/fuzz.sh TARGET SECONDS   build build-fuzz/ (clang, ASan, UBSan, libFuzzer) if needed and
#                                  fuzz TARGET for SECONDS on a copy of tests/fuzz/corpus/TARGET
#   tools/fuzz.sh --list           the targets
#   tools/fuzz.sh --help
#
# The work folder is ${XDG_CACHE_HOME:-~/.cache}/mocap/fuzz/TARGET (corpus/ grows there; crashes,
# leaks, timeouts and out-of-memory inputs land in artifacts/); nothing is written into the
# repository. Environment: MOCAP_FUZZ_JOBS (build jobs, default 2), MOCAP_FUZZ_RSS_MB (memory limit,
# default 2048), MOCAP_FUZZ_TIMEOUT (seconds for one input, default 10), MOCAP_FUZZ_ARGS (more
# libFuzzer flags). Exit code: 0 without findings, 1 when the fuzzer found something, 2 on usage.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir="$repo/build-fuzz"
fuzz_dir="$repo/tests/fuzz"

targets() {
  for f in "$fuzz_dir"/*.cpp; do
    name=$(basename "$f" .cpp)
    [[ $name == replay_main ]] || echo "$name"
  done
}

usage() { sed -n '2,13p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }

case "${1:-}" in
  -h|--help) usage; exit 0 ;;
  --list) targets; exit 0 ;;
  "") usage >&2; exit 2 ;;
esac
target=$1
seconds=${2:-}
if ! grep -qx -- "$target" <<<"$(targets)"; then
  echo "fuzz.sh: unknown target '$target'; targets: $(targets | tr '\n' ' ')" >&2
  exit 2
fi
if ! [[ $seconds =~ ^[0-9]+$ ]] || (( seconds < 1 )); then
  echo "fuzz.sh: SECONDS must be a positive whole number (see --help)" >&2
  exit 2
fi
for tool in clang clang++; do
  command -v "$tool" >/dev/null || { echo "fuzz.sh: $tool not found (tools/setup.sh installs it)" >&2; exit 2; }
done

if [[ ! -f $build_dir/build.ninja ]]; then
  CC=clang CXX=clang++ cmake -S "$repo" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DMOCAP_FUZZ=ON -DMOCAP_WITH_FAISS=OFF >/dev/null
fi
cmake --build "$build_dir" -j "${MOCAP_FUZZ_JOBS:-2}" --target "fuzz_$target"

work="${XDG_CACHE_HOME:-$HOME/.cache}/mocap/fuzz/$target"
mkdir -p "$work/corpus" "$work/artifacts"
cp -n "$fuzz_dir/corpus/$target"/* "$work/corpus/" 2>/dev/null || true
before=$(ls "$work/artifacts" | wc -l)
log="$work/fuzz.log"

echo "fuzz.sh: $target for $seconds s in $work (log: $log)"
set +e
# Run from the work folder: anything a target wrote by mistake would land there, not in the repo.
(cd "$work" && "$build_dir/bin/fuzz_$target" -max_total_time="$seconds" \
  -rss_limit_mb="${MOCAP_FUZZ_RSS_MB:-2048}" -timeout="${MOCAP_FUZZ_TIMEOUT:-10}" \
  -artifact_prefix="$work/artifacts/" -print_final_stats=1 ${MOCAP_FUZZ_ARGS:-} "$work/corpus") \
  >"$log" 2>&1
status=$?
set -e

execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1 || true)
elapsed=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$log" | grep -o 'in [0-9]*' | grep -o '[0-9]*' | tail -1 || true)
after=$(ls "$work/artifacts" | wc -l)
findings=$((after - before))
echo "fuzz.sh: target $target: executions ${execs:-?}, seconds ${elapsed:-?}," \
  "corpus $(ls "$work/corpus" | wc -l) files ($(du -sk "$work/corpus" | cut -f1) KB)," \
  "findings $findings (exit $status)"
if (( findings > 0 || status != 0 )); then
  grep -E '^==[0-9]+==ERROR|^SUMMARY|runtime error|fuzz target:|deadly signal|Test unit written' \
    "$log" | head -20 || true
  ls -t "$work/artifacts" | head -5 | sed "s|^|  $work/artifacts/|"
  exit 1
fi
