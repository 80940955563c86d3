#!/usr/bin/env bash
# What recording a rover's whole output to MCAP costs (issue 29): canyon rover (fusion, downtown, 5 Hz, in real time,
# publish_stages and ros2 on) publishes for DURATION seconds while `canyon record` takes every topic it publishes
# into one MCAP file and, beside it, one `canyon record` per canyon topic writes canyon's own files (.csv for the
# solutions and the timing, text lines for the stage outputs; the ROS 2 topics have no own format and are left out
# of the size comparison). Prints the CPU seconds of the rover and of the MCAP recorder (their ratio: the
# recorder's share of the rover's CPU; and the own-file recorders' CPU beside it), and the MCAP file's size against the canyon topics' own files (and the MCAP
# size of those topics alone, from its channel byte counts).
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
pids=()
TIMEFORMAT='%3U %3S'
{ time "$canyon" record "${canyon_topics[@]}" rt/canyon/fix rt/canyon/odometry rt/diagnostics --out "$tmp/session.mcap" \
    --domain "$domain" 2> "$tmp/mcap.log"; } 2> "$tmp/mcap.cpu" &
pids+=($!)
for k in "${!canyon_topics[@]}"; do
  { time "$canyon" record "${canyon_topics[$k]}" --out "$tmp/own/${own_out[$k]}" --domain "$domain" \
      2> "$tmp/own_$k.log"; } 2> "$tmp/own_$k.cpu" &
  pids+=($!)
done
mkdir -p "$tmp/own"
sleep 3
{ time "$canyon" rover --config "$tmp/rover.yaml" -q --wait-for-subscribers 5 --wait-timeout 30; } 2> "$tmp/rover.cpu"
for p in "${pids[@]}"; do wait "$p"; done
cpu() { awk '{printf "%.2f", $1 + $2}' "$1"; }
rover_cpu=$(cpu "$tmp/rover.cpu")
mcap_cpu=$(cpu "$tmp/mcap.cpu")
own_cpu=$(cat "$tmp"/own_*.cpu | awk '{s += $1 + $2} END {printf "%.2f", s}')
own_bytes=$(cat "$tmp"/own/* | wc -c)
mcap_bytes=$(stat -c %s "$tmp/session.mcap")
cat "$tmp/mcap.log"
python3 - "$tmp/session.mcap" "$rover_cpu" "$mcap_cpu" "$own_bytes" "$mcap_bytes" "$duration" "$own_cpu" << 'PY'
import struct, sys
path, rover_cpu, mcap_cpu, own, total, duration = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), sys.argv[6]
own_cpu = float(sys.argv[7])
data = open(path, "rb").read()
at, topics, per_channel = 8, {}, {}
while at + 9 <= len(data):
    op, n = data[at], struct.unpack_from("<Q", data, at + 1)[0]
    c = data[at + 9: at + 9 + n]
    if op == 0x04:
        cid = struct.unpack_from("<H", c, 0)[0]; l = struct.unpack_from("<I", c, 4)[0]
        topics[cid] = c[8:8 + l].decode()
    elif op == 0x05:
        cid = struct.unpack_from("<H", c, 0)[0]
        per_channel[cid] = per_channel.get(cid, 0) + 9 + n
    elif op == 0x0F:
        break
    at += 9 + n
canyon_bytes = sum(b for cid, b in per_channel.items() if not topics[cid].startswith("rt/"))
print("duration %s s at 5 Hz: rover CPU %.2f s, MCAP recorder CPU %.2f s = %.1f %% of the rover's; the six "
      "recorders of canyon's own files %.2f s together (6 of the 9 topics)" %
      (duration, rover_cpu, mcap_cpu, 100.0 * mcap_cpu / rover_cpu, own_cpu))
print("MCAP file %d bytes (all 9 topics); the 6 canyon topics' messages in it %d bytes against their own files %d "
      "bytes: %.2fx" % (total, canyon_bytes, own, canyon_bytes / own))
PY
