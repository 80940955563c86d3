#!/usr/bin/env bash
# ROS 2 on the wire: canyon rover (ros2.enabled) on a 60 s downtown walk publishes NavSatFix, Odometry and
# DiagnosticArray on ROS 2's names (rt/canyon/fix, rt/canyon/odometry, rt/diagnostics) and type names; canyon_ros2_raw
# takes the samples off the wire as raw bytes (no canyon IDL) with ROS 2's QoS profiles; wire_check.mjs decodes them
# with independent ROS 2 decoders driven by the upstream .msg definitions and compares each with the rover's .pos.
# canyon record writes the same session, every topic the rover publishes, to MCAP (zstd chunks): mcap_check.mjs reads
# it with the MCAP and OMG IDL packages of the npm registry, decodes every message and compares the solutions with the
# .pos; mcap_indexed.mjs reads it through its indexes, as Foxglove does. Then canyon play (round trip, bad input), the
# rover's VIO from ROS 2 Odometry (independently encoded, and from canyon vio --ros2), canyon base's rt/rtcm
# (rtcm_msgs/msg/Message), and bad Odometry.
# Usage: tests/ros2/wire_check.sh BUILD_DIR
# Exit 0 pass, 1 fail, 77 (SKIP:) no npm or the npm registry unreachable for the decoders.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "${1:?usage: wire_check.sh BUILD_DIR}" && pwd)
canyon=$build/canyon
raw=$build/tests/canyon_ros2_raw
[[ -x $canyon && -x $raw ]] || { echo "error: build canyon and canyon_ros2_raw first" >&2; exit 1; }
# The decoders, a scratch folder, cleanup on exit, a domain of its own.
source "$here/common.sh" "$build" ros2-decoders
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
dds: {domain: $domain, record: $tmp/inproc.mcap}
ros2: {enabled: true}
EOF
record() {  # topic type qos file count (0: until 5 s without a sample)
  "$raw" record --topic "$1" --type "$2" --qos "$3" --out "$tmp/$4" --count "$5" --timeout "$([[ $5 == 0 ]] && echo 5 || echo 30)" \
    --domain "$domain" 2> "$tmp/$4.log" &
  pids+=($!)
}
record rt/canyon/fix sensor_msgs::msg::dds_::NavSatFix_ sensor fix.bin "$epochs"
record rt/canyon/odometry nav_msgs::msg::dds_::Odometry_ sensor odom.bin 0  # from the first fix on
record rt/diagnostics diagnostic_msgs::msg::dds_::DiagnosticArray_ default diag.bin "$epochs"
# The same session recorded to MCAP: every topic the rover publishes, read back below by the independent reader.
session_topics=(canyon/solution canyon/timing canyon/prior canyon/float canyon/bridged canyon/alignment rt/canyon/fix
                rt/canyon/odometry rt/diagnostics)
"$canyon" record "${session_topics[@]}" --out "$tmp/session.mcap" --domain "$domain" 2> "$tmp/mcap.log" &
mcap_pid=$!
sleep 2  # every reader of the recorder discovered (the rover waits for the solution and ROS 2 ones only)
"$canyon" rover --config "$tmp/rover.yaml" -q --wait-for-subscribers 7 --wait-timeout 30
for p in "${pids[@]}"; do wait "$p" || { echo "FAIL: a recorder missed samples: $(cat "$tmp"/*.log)"; exit 1; }; done
cat "$tmp"/*.bin.log
node "$decoders/wire_check.mjs" "$tmp"
wait "$mcap_pid" || { echo "FAIL: canyon record to MCAP: $(cat "$tmp/mcap.log")"; exit 1; }
cat "$tmp/mcap.log"
node "$decoders/mcap_check.mjs" "$tmp/session.mcap" "$tmp/rover.pos" "$epochs" "${session_topics[@]}"
node "$decoders/mcap_indexed.mjs" "$tmp/session.mcap" "$(grep -o '[0-9]* samples' "$tmp/mcap.log" | cut -d' ' -f1)"
# The rover's own in-process recording (dds.record) holds the same samples as canyon record took off the wire.
node "$decoders/mcap_same.mjs" "$tmp/session.mcap" "$tmp/inproc.mcap" "dds.record (in-process) against canyon record" \
  --decoded
# Bad input to canyon record: a topic it has no schema for, several topics without MCAP, an MCAP path that cannot be
# written: each a clear error, nothing started.
expect_error() {  # exit-code message args...
  local code=$1 message=$2 rc=0
  shift 2
  "$canyon" record "$@" --domain "$domain" > "$tmp/err.log" 2>&1 || rc=$?
  [[ $rc -eq $code ]] && grep -qF "$message" "$tmp/err.log" ||
    { echo "FAIL: canyon record $*: exit $rc, $(cat "$tmp/err.log") (expected $code, '$message')"; exit 1; }
}
expect_error 2 "unknown topic 'foo/bar'" canyon/solution foo/bar --out "$tmp/x.mcap"
expect_error 2 "several topics need a recording to .mcap" canyon/solution canyon/timing --out "$tmp/x.csv"
expect_error 1 "/dev/null/x.mcap: cannot create the MCAP file" canyon/solution --out /dev/null/x.mcap --duration 1
echo "canyon record bad input: unknown topic, several topics without MCAP, unwritable MCAP path: named"

# canyon play: the session published again and recorded again equals it byte for byte (read by @mcap/core).
"$canyon" record "${session_topics[@]}" --out "$tmp/replayed.mcap" --domain "$domain" 2> "$tmp/replay.log" &
replay_pid=$!
sleep 2
"$canyon" play "$tmp/session.mcap" --pace 5 --domain "$domain" --wait-for-readers 1 -q
wait "$replay_pid"
node "$decoders/mcap_same.mjs" "$tmp/session.mcap" "$tmp/replayed.mcap"
# Bad input to canyon play: a file another writer (@mcap/core) made with a channel of a type canyon does not know
# plays the rest, naming the channel; a file cut short plays what came before the cut, naming the byte; not an MCAP
# file is an error.
node "$decoders/mcap_foreign.mjs" "$tmp/session.mcap" "$tmp/foreign.mcap"
"$canyon" play "$tmp/foreign.mcap" --pace 0 --domain "$domain" --linger 0 > "$tmp/foreign.log" 2>&1
grep -qF "channel 1 ('foo/bar', schema 'foo::msg::Bar') is not one canyon knows: left out" "$tmp/foreign.log" &&
  grep -qF "canyon/solution: $epochs messages played" "$tmp/foreign.log" ||
  { echo "FAIL: canyon play of a foreign channel:"; cat "$tmp/foreign.log"; exit 1; }
head -c $(($(stat -c %s "$tmp/session.mcap") / 2)) "$tmp/session.mcap" > "$tmp/cut.mcap"
"$canyon" play "$tmp/cut.mcap" --pace 0 --domain "$domain" --linger 0 > "$tmp/cut.log" 2>&1
grep -q "cut.mcap: cut short at byte [0-9]* (.*); playing the [0-9]* messages before it" "$tmp/cut.log" ||
  { echo "FAIL: canyon play of a cut file:"; cat "$tmp/cut.log"; exit 1; }
rc=0
"$canyon" play "$tmp/rover.pos" --domain "$domain" > "$tmp/notmcap.log" 2>&1 || rc=$?
[[ $rc -eq 1 ]] && grep -qF "not an MCAP file" "$tmp/notmcap.log" ||
  { echo "FAIL: canyon play of a .pos: exit $rc, $(cat "$tmp/notmcap.log")"; exit 1; }
echo "canyon play bad input: a foreign channel left out and named, a cut file played up to the cut, a .pos refused"

# VIO in: Odometry -> canyon rover equals the same poses from a file (vio_gps.csv: the poses on GPST, no
# cross-covariances, as Odometry carries none).
node "$decoders/encode_odometry.mjs" "$tmp/sim/vio.csv" "$tmp/sim/timesync.csv" "$tmp"
vio_rover() {  # name vio-source
  cat > "$tmp/$1.yaml" << EOF
estimator:
  mode: fusion
  rover: $tmp/sim/rover.obs
  base: $tmp/sim/base.obs
  nav: [$tmp/sim/nav.rnx]
  vio: $tmp/vio_gps.csv
  fusion: {vio_clock: gps}
  out: $tmp/$1.pos
rover_id: walker
input: {pace: 5, vio: $2, vio_wait_s: 5}
dds: {domain: $domain}
EOF
}
vio_rover from_file file
vio_rover from_ros2 ros2
"$canyon" rover --config "$tmp/from_file.yaml" -q > "$tmp/from_file.log" 2>&1
publish() {  # frames-file log
  "$raw" publish --topic rt/vio/odometry --type nav_msgs::msg::dds_::Odometry_ --qos default --in "$1" --rate 200 \
    --wait-readers 1 --timeout 30 --domain "$domain" 2> "$2" &
  pids+=($!)
}
publish "$tmp/odometry.bin" "$tmp/publish.log"
"$canyon" rover --config "$tmp/from_ros2.yaml" -q > "$tmp/from_ros2.log" 2>&1
wait "${pids[-1]}" || { echo "FAIL: publishing the Odometry: $(cat "$tmp/publish.log")"; exit 1; }
if ! cmp -s <(grep -v '^%' "$tmp/from_file.pos") <(grep -v '^%' "$tmp/from_ros2.pos"); then
  echo "FAIL: the Odometry-driven rover differs from the same poses from a file:"
  grep -h "VIO over DDS\|sample dropped" "$tmp/from_ros2.log" "$tmp/publish.log" || true
  diff <(grep -v '^%' "$tmp/from_file.pos") <(grep -v '^%' "$tmp/from_ros2.pos") | head -5
  exit 1
fi
echo "input.vio ros2: $(grep -vc '^%' "$tmp/from_ros2.pos") solutions equal, byte for byte, to the same poses from a file"

# canyon vio --ros2, a ROS 2 VIO node: its Odometry, off the wire, equals the independently encoded poses, and drives
# the rover to the same solutions, byte for byte, as the file.
poses=$(($(wc -l < "$tmp/vio_gps.csv") - 1))
vio_rover from_canyon_vio ros2
record rt/vio/odometry nav_msgs::msg::dds_::Odometry_ default vio_odom.bin "$poses"
odom_rec=$!
"$canyon" vio --vio "$tmp/vio_gps.csv" --ros2 --pace 0 --wait-for-readers 2 --domain "$domain" -q > "$tmp/vio.log" 2>&1 &
vio_pid=$!
pids+=("$vio_pid")
"$canyon" rover --config "$tmp/from_canyon_vio.yaml" -q > "$tmp/from_canyon_vio.log" 2>&1
wait "$vio_pid" || { echo "FAIL: canyon vio --ros2: $(cat "$tmp/vio.log")"; exit 1; }
wait "$odom_rec" || { echo "FAIL: recording canyon vio's Odometry: $(cat "$tmp/vio_odom.bin.log")"; exit 1; }
node "$decoders/streams_check.mjs" odometry "$tmp/vio_odom.bin" "$tmp/odometry.bin"
if ! cmp -s <(grep -v '^%' "$tmp/from_file.pos") <(grep -v '^%' "$tmp/from_canyon_vio.pos"); then
  echo "FAIL: the rover on canyon vio --ros2 differs from the same poses from a file:"
  diff <(grep -v '^%' "$tmp/from_file.pos") <(grep -v '^%' "$tmp/from_canyon_vio.pos") | head -5
  exit 1
fi
echo "canyon vio --ros2 -> canyon rover input.vio ros2: the same $(grep -vc '^%' "$tmp/from_file.pos") solutions"
rc=0
"$canyon" vio --vio "$tmp/sim/vio.csv" --timesync "$tmp/sim/timesync.csv" --ros2 > "$tmp/vio_bad.log" 2>&1 || rc=$?
[[ $rc -eq 2 ]] && grep -qF "needs poses stamped with GPST: leave out --timesync" "$tmp/vio_bad.log" ||
  { echo "FAIL: canyon vio --ros2 --timesync: exit $rc, $(cat "$tmp/vio_bad.log")"; exit 1; }

# canyon base outputs.ros2: every RTCM 3 frame as rtcm_msgs/msg/Message; decoded independently and joined, the
# frames are the base's canyon/rtcm stream byte for byte, and RTKLIB's convbin reads that stream back to every epoch.
cat > "$tmp/base.yaml" << EOF
input: {kind: rinex, source: file, path: $tmp/sim/base.obs, nav: [$tmp/sim/nav.rnx], pace: 10}
outputs:
  dds: {enabled: true, domain: $domain}
  ntrip: {enabled: false}
  ros2: {enabled: true, frame_id: base_antenna}
log: {progress_interval_s: 0}
EOF
record rt/rtcm rtcm_msgs::msg::dds_::Message_ default rtcm.bin 0
rtcm_ros2=$!
"$canyon" record canyon/rtcm --out "$tmp/base.rtcm3" --domain "$domain" > "$tmp/rtcm_rec.log" 2>&1 &
rtcm_rec=$!
pids+=("$rtcm_rec")
"$canyon" base --config "$tmp/base.yaml" --wait-for-clients 2 -q
wait "$rtcm_ros2" || { echo "FAIL: recording rt/rtcm: $(cat "$tmp/rtcm.bin.log")"; exit 1; }
kill -INT "$rtcm_rec" 2> /dev/null || true  # it ends by itself once the base has left
wait "$rtcm_rec" || { echo "FAIL: canyon record canyon/rtcm: $(cat "$tmp/rtcm_rec.log")"; exit 1; }
node "$decoders/streams_check.mjs" rtcm "$tmp/rtcm.bin" "$tmp/base.rtcm3" base_antenna
base_epochs=$(grep -c '^>' "$tmp/sim/base.obs")
# convbin's -tr takes the date and the time as two arguments.
read -r day clock < <(awk '/TIME OF FIRST OBS/ {printf "%04d/%02d/%02d %02d:%02d:%02d\n", $1, $2, $3, $4, $5, $6}' "$tmp/sim/base.obs")
mkdir -p "$tmp/convbin"
convbin -r rtcm3 -v 3.04 -tr "$day" "$clock" -d "$tmp/convbin" "$tmp/base.rtcm3" > /dev/null 2>&1 || true
read_back=$(grep -c '^>' "$tmp/convbin/base.obs" 2> /dev/null || true)
[[ ${read_back:-0} -eq $base_epochs ]] ||
  { echo "FAIL: RTKLIB convbin read ${read_back:-0} epochs of the ROS 2 RTCM stream, the base file has $base_epochs"; exit 1; }
echo "RTKLIB convbin: the RTCM 3 stream carried on ROS 2 holds all $base_epochs base epochs"

# Bad input: refused sample by sample, each named.
node "$decoders/encode_odometry.mjs" "$tmp/sim/vio.csv" "$tmp/sim/timesync.csv" "$tmp" --bad
publish "$tmp/odometry.bin" "$tmp/publish_bad.log"
"$canyon" rover --config "$tmp/from_ros2.yaml" > "$tmp/bad.log" 2>&1
wait "${pids[-1]}" || { echo "FAIL: publishing the bad Odometry: $(cat "$tmp/publish_bad.log")"; exit 1; }
for what in "pose or its covariance is not finite" "frames 'world' -> 'imu', expected 'odom' -> 'imu'" \
  "frames 'odom' -> 'camera', expected 'odom' -> 'imu'"; do
  grep -qF "$what" "$tmp/bad.log" || { echo "FAIL: the log does not name '$what':"; grep -i "vio\|warn" "$tmp/bad.log" | head; exit 1; }
done
solved=$(grep -v '^%' "$tmp/from_ros2.pos" | awk '$6 != 0' | wc -l)
[[ $solved -eq $epochs ]] || { echo "FAIL: $solved of $epochs epochs solved with three bad Odometry samples"; exit 1; }
grep "sample dropped" "$tmp/bad.log" | sed 's/^.*VIO/VIO/' | head -3
echo "bad Odometry: 3 samples refused and named, all $epochs epochs solved"
