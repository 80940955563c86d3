#!/usr/bin/env bash
# ROS 2 on the wire: canyon rover (ros2.enabled) on a 60 s downtown walk publishes NavSatFix, Odometry and
# DiagnosticArray on ROS 2's names (rt/canyon/fix, rt/canyon/odometry, rt/diagnostics) and type names; canyon_ros2_raw
# takes the samples off the wire as raw bytes (no canyon IDL) with ROS 2's QoS profiles; wire_check.mjs decodes them
# with independent ROS 2 decoders driven by the upstream .msg definitions and compares each with the rover's .pos.
# Usage: tests/ros2/wire_check.sh BUILD_DIR
# Exit 0 pass, 1 fail, 77 (SKIP:) no npm or the npm registry unreachable for the decoders.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "${1:?usage: wire_check.sh BUILD_DIR}" && pwd)
canyon=$build/canyon
raw=$build/tests/canyon_ros2_raw
[[ -x $canyon && -x $raw ]] || { echo "error: build canyon and canyon_ros2_raw first" >&2; exit 1; }
command -v npm > /dev/null || { echo "SKIP: npm not found (scripts/setup.sh installs it)"; exit 77; }

# The decoders, locked, into the build folder (never the source tree); install scripts are not run.
decoders=$build/ros2-decoders
mkdir -p "$decoders"
cp "$here/package.json" "$here/package-lock.json" "$here/wire_check.mjs" "$decoders/"
if [[ ! -f $decoders/node_modules/.package-lock.json || $here/package-lock.json -nt $decoders/node_modules/.package-lock.json ]]; then
  (cd "$decoders" && npm ci --no-audit --no-fund --ignore-scripts --loglevel=error) ||
    { echo "SKIP: npm ci failed for the ROS 2 decoders (is the npm registry reachable?)"; exit 77; }
fi

tmp=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2> /dev/null || true; done
  rm -rf "$tmp"
}
trap cleanup EXIT
domain=$((100 + RANDOM % 100))
"$canyon" simulate -q --scenario downtown --seed 3 --duration 60 --out "$tmp/sim"
epochs=$(grep -c '^[0-9]' "$tmp/sim/truth.csv")
cat > "$tmp/rover.yaml" << EOF
estimator:
  mode: fusion
  rover: $tmp/sim/rover.obs
  base: $tmp/sim/base.obs
  nav: [$tmp/sim/nav.rnx]
  vio: $tmp/sim/vio.csv
  timesync: $tmp/sim/timesync.csv
  out: $tmp/rover.pos
rover_id: walker
input: {pace: 5}
dds: {domain: $domain}
ros2: {enabled: true}
EOF
record() {  # topic type qos file
  "$raw" record --topic "$1" --type "$2" --qos "$3" --out "$tmp/$4" --count "$epochs" --timeout 30 \
    --domain "$domain" 2> "$tmp/$4.log" &
  pids+=($!)
}
record rt/canyon/fix sensor_msgs::msg::dds_::NavSatFix_ sensor fix.bin
record rt/canyon/odometry nav_msgs::msg::dds_::Odometry_ sensor odom.bin
record rt/diagnostics diagnostic_msgs::msg::dds_::DiagnosticArray_ default diag.bin
"$canyon" rover --config "$tmp/rover.yaml" -q --wait-for-subscribers 3 --wait-timeout 30
for p in "${pids[@]:0:1}" "${pids[@]:2:1}"; do wait "$p" || { echo "FAIL: a recorder missed samples: $(cat "$tmp"/*.log)"; exit 1; }; done
kill "${pids[1]}" 2> /dev/null || true  # Odometry starts at the first fix: fewer samples than epochs
wait "${pids[1]}" 2> /dev/null || true
cat "$tmp"/*.bin.log
node "$decoders/wire_check.mjs" "$tmp"
