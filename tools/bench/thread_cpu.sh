#!/bin/bash
# CPU seconds per thread name of a command, e.g. where a graph's cores go (node threads carry
# their node's name; helper threads inherit it):
#   tools/bench/thread_cpu.sh OUT.txt -- build/bin/mocap reconstruct VIDEO --out DIR
# Samples /proc/PID/task/*/stat every 0.3 s (a thread that ends keeps its last sample), then
# writes "name seconds" lines, largest first, to OUT.txt. Exits with the command's status.
set -u
if [ $# -lt 3 ] || [ "$2" != "--" ]; then
  echo "usage: $0 OUT.txt -- COMMAND [ARGS...]" >&2
  exit 2
fi
out=$1
shift 2
samples=$(mktemp)
trap 'rm -f "$samples"' EXIT
"$@" &
pid=$!
ticks=$(getconf CLK_TCK)
while kill -0 "$pid" 2>/dev/null; do
  for task in /proc/"$pid"/task/*; do
    stat=$(cat "$task"/stat 2>/dev/null) || continue
    name=$(cat "$task"/comm 2>/dev/null) || continue
    rest=${stat##*) }  # the fields after "(comm)": utime and stime are the 12th and 13th
    read -ra f <<<"$rest"
    echo "${task##*/} ${name// /_} $((f[11] + f[12]))" >>"$samples"
  done
  sleep 0.3
done
wait "$pid"
status=$?
awk -v hz="$ticks" '{ if ($3 >= m[$1]) { m[$1] = $3; n[$1] = $2 } }
  END { for (t in m) s[n[t]] += m[t]; for (k in s) printf "%-16s %7.1f s\n", k, s[k] / hz }' \
  "$samples" | sort -k2 -nr >"$out"
exit "$status"
