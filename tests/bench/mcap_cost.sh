#!/usr/bin/env bash
# What recording a rover's whole output to MCAP costs (issue 29): canyon rover (fusion, downtown, 5 Hz, in real time,
# publish_stages and ros2 on) publishes for DURATION seconds while `canyon record` takes every topic it publishes
# into one MCAP file and, beside it, one `canyon record` per canyon topic writes canyon's own files (.csv for the
# solutions and the timing, text lines for the stage outputs; the ROS 2 topics have no own format and are left out
# of the size comparison). Prints the CPU seconds of the rover and of the MCAP recorder (their ratio: the
# recorder's share of the rover's CPU; and the own-file recorders' CPU beside it); then the rover again, recording
# what it publishes itself (dds.record, in-process), which reports its recording's CPU against its own. Sizes: the six
# canyon topics as one MCAP file (zstd chunks) against the same streams as canyon's own files.
# Usage: tests/bench/mcap_cost.sh [BUILD_DIR] [DURATION_S]   (defaults: build, 120)
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
duration=${2:-120}
canyon=$build/canyon
[[ -x $canyon ]] || { echo "error: $canyon not built" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
domain=$((100 + RANDOM % 100))
"$canyon" simulate -q --scenario downtown --seed 3 --duration "$duration" --out "$tmp/sim"
cat > "$tmp/rover.yaml" << EOF
estimator:
  mode: fusion
  rover: $tmp/sim/rover.obs
  base: $tmp/sim/base.obs
  nav: [$tmp/sim/nav.rnx]
  vio: $tmp/sim/vio.csv
  timesync: $tmp/sim/timesync.csv
rover_id: walker
input: {pace: 1}
dds: {domain: $domain, publish_stages: true}
ros2: {enabled: true}
EOF
canyon_topics=(canyon/solution canyon/timing canyon/prior canyon/float canyon/bridged canyon/alignment)
own_out=(solution.csv timing.csv prior.txt float.txt bridged.txt alignment.txt)
mkdir -p "$tmp/own"
TIMEFORMAT='%3U %3S'
cpu() { awk '{printf "%.2f", $1 + $2}' "$1"; }

# Run 1: canyon record (a separate process, a DDS reader per topic) takes every topic the rover publishes into one
# MCAP file; beside it, one canyon record per canyon topic writes canyon's own files, and one more takes the six
# canyon topics alone into MCAP (the size comparison: the same streams as MCAP and as canyon's own files).
pids=()
{ time "$canyon" record "${canyon_topics[@]}" rt/canyon/fix rt/canyon/odometry rt/diagnostics --out "$tmp/session.mcap" \
    --domain "$domain" 2> "$tmp/mcap.log"; } 2> "$tmp/mcap.cpu" &
pids+=($!)
"$canyon" record "${canyon_topics[@]}" --out "$tmp/canyon_topics.mcap" --domain "$domain" 2> "$tmp/canyon_topics.log" &
pids+=($!)
for k in "${!canyon_topics[@]}"; do
  { time "$canyon" record "${canyon_topics[$k]}" --out "$tmp/own/${own_out[$k]}" --domain "$domain" \
      2> "$tmp/own_$k.log"; } 2> "$tmp/own_$k.cpu" &
  pids+=($!)
done
sleep 3
{ time "$canyon" rover --config "$tmp/rover.yaml" -q --wait-for-subscribers 6 --wait-timeout 30; } 2> "$tmp/rover.cpu"
for p in "${pids[@]}"; do wait "$p"; done
cat "$tmp/mcap.log"

# Run 2: the rover records what it publishes itself (dds.record): no reader, the samples serialized on its threads.
sed "s|^dds: {|dds: {record: $tmp/inproc.mcap, |" "$tmp/rover.yaml" > "$tmp/rover_record.yaml"
{ time "$canyon" rover --config "$tmp/rover_record.yaml" > "$tmp/rover_record.log" 2>&1; } 2> "$tmp/rover_record.cpu"
grep "recorded .* messages" "$tmp/rover_record.log" | sed 's/^.*\] //'

rover_cpu=$(cpu "$tmp/rover.cpu")
mcap_cpu=$(cpu "$tmp/mcap.cpu")
own_cpu=$(cat "$tmp"/own_*.cpu | awk '{s += $1 + $2} END {printf "%.2f", s}')
own_bytes=$(cat "$tmp"/own/* | wc -c)
canyon_mcap_bytes=$(stat -c %s "$tmp/canyon_topics.mcap")
echo "duration $duration s at 5 Hz:"
awk -v r="$rover_cpu" -v m="$mcap_cpu" -v o="$own_cpu" 'BEGIN {
  printf "  canyon record (separate process, all 9 topics): %.2f s of CPU against the rover'"'"'s %.2f s = %.1f %%; the six own-file recorders %.2f s together\n", m, r, 100 * m / r, o }'
inproc=$(grep -o "recording took [0-9.]* s of CPU, [0-9.]* % of the rover's [0-9.]* s" "$tmp/rover_record.log")
echo "  dds.record (in-process, all 9 topics): $inproc"
awk -v m="$canyon_mcap_bytes" -v o="$own_bytes" -v a="$(stat -c %s "$tmp/session.mcap")" -v i="$(stat -c %s "$tmp/inproc.mcap")" 'BEGIN {
  printf "  size: the six canyon topics as MCAP (zstd chunks) %d bytes against their own files %d bytes: %.2fx; all 9 topics: %d bytes (canyon record), %d bytes (dds.record)\n", m, o, m / o, a, i }'
