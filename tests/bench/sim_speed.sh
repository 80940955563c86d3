#!/usr/bin/env bash
# Generation speed of canyon simulate: a 1-hour scenario at 5 Hz (18001 rover epochs, base at 1 Hz), whole-process
# wall time including writing every file, median of RUNS runs per scenario.
# Usage: tests/bench/sim_speed.sh [BUILD_DIR] [RUNS] [DURATION_S]      (defaults: build, 3, 3600)
# Exit status: 0 done, 1 a run took a minute or more, 2 missing build.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
runs=${2:-3}
duration=${3:-3600}
canyon=$build/canyon
[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

median() { sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
status=0
printf '%-15s %8s %10s %12s %10s\n' scenario epochs "wall s" "rover MB" "limit 60 s"
for scenario in open-sky light-blocked urban-moderate urban-severe; do
  times=()
  for ((i = 0; i < runs; i++)); do
    start=$(date +%s.%N)
    "$canyon" simulate -q --scenario "$scenario" --duration "$duration" --out "$tmp/$scenario"
    times+=("$(awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN {printf "%.2f", e - s}')")
  done
  wall=$(printf '%s\n' "${times[@]}" | median)
  epochs=$(grep -c '^> ' "$tmp/$scenario/rover.obs")
  size=$(awk -v b="$(stat -c %s "$tmp/$scenario/rover.obs")" 'BEGIN {printf "%.1f", b / 1e6}')
  ok=$(awk -v w="$wall" 'BEGIN {print (w < 60) ? "ok" : "TOO SLOW"}')
  [[ $ok == ok ]] || status=1
  printf '%-15s %8s %10s %12s %10s\n' "$scenario" "$epochs" "$wall" "$size" "$ok"
done
exit $status
