#!/usr/bin/env bash
# A field session re-run at the desk. Live: canyon base (RTCM 3 from the base's RINEX), canyon vio (VIO and time-sync
# pairs) and canyon rover (fusion; its receiver replayed from a file) on DDS, canyon record writing the rover's inputs
# and outputs to live.mcap. At the desk: canyon play publishes the rover's inputs from live.mcap (canyon/rtcm,
# canyon/vio, canyon/timesync) to a new rover, canyon record writes its outputs to replay.mcap. The two rovers' .pos are
# the same byte for byte, and the solutions in replay.mcap, read by the independent MCAP reader, equal the live .pos.
# Usage: tests/ros2/replay_check.sh BUILD_DIR
# Exit 0 pass, 1 fail, 77 (SKIP:) no npm or the npm registry unreachable for the decoders.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "${1:?usage: replay_check.sh BUILD_DIR}" && pwd)
canyon=$build/canyon
[[ -x $canyon ]] || { echo "error: build canyon first" >&2; exit 1; }
# The decoders, a scratch folder, cleanup on exit, a domain of its own.
source "$here/common.sh" "$build" ros2-decoders-replay
"$canyon" simulate -q --scenario downtown --seed 4 --duration 60 --out "$tmp/sim"
epochs=$(grep -c '^[0-9]' "$tmp/sim/truth.csv")
rover_config() {  # name: the rover's inputs from DDS, its .pos beside
  cat > "$tmp/$1.yaml" << EOF
estimator:
  mode: fusion
  rover: $tmp/sim/rover.obs
  nav: [$tmp/sim/nav.rnx]
  out: $tmp/$1.pos
rover_id: walker
input: {pace: 5, base: dds, base_wait_s: 10, vio: dds, vio_wait_s: 5}
dds: {domain: $domain, publish_stages: false, publish_observations: true}
EOF
}
rover_config live
rover_config replay
cat > "$tmp/base.yaml" << EOF
input: {kind: rinex, source: file, path: $tmp/sim/base.obs, nav: [$tmp/sim/nav.rnx], pace: 10}
outputs: {dds: {enabled: true, domain: $domain}, ntrip: {enabled: false}}
log: {progress_interval_s: 0}
EOF
inputs=(canyon/rtcm canyon/vio canyon/timesync)
outputs=(canyon/solution canyon/timing)
observations=canyon/observations  # the rover's epochs as ingested: the session then holds every rover input

# Live. The VIO node publishes its whole run at once and stays up: its topics keep the last 1024 samples for readers
# that join late (the rover), so the rover has the VIO from its first epoch whenever it starts; the base runs ahead of
# the rover (pace 10 against 5), so every rover epoch has its base epoch.
# (live.mcap unchunked, --mcap-compression "": canyon's other layout; replay.mcap zstd chunks, the default)
"$canyon" record "${inputs[@]}" "${outputs[@]}" "$observations" --out "$tmp/live.mcap" --mcap-compression "" \
  --domain "$domain" 2> "$tmp/live_rec.log" &
live_rec=$!
pids+=("$live_rec")
"$canyon" vio --vio "$tmp/sim/vio.csv" --timesync "$tmp/sim/timesync.csv" --pace 0 --wait-for-readers 1 --linger 120 \
  --domain "$domain" -q &
vio=$!
pids+=("$vio")
"$canyon" base --config "$tmp/base.yaml" --wait-for-clients 2 -q &
base=$!
pids+=("$base")
"$canyon" rover --config "$tmp/live.yaml" -q --wait-for-subscribers 1 --wait-timeout 30
wait "$base"
kill -INT "$vio" "$live_rec"
wait "$vio" || true
wait "$live_rec" || { echo "FAIL: canyon record (live): $(cat "$tmp/live_rec.log")"; exit 1; }
cat "$tmp/live_rec.log"

# At the desk: the rover's inputs played from the recording, at the recorded pace.
"$canyon" record "${outputs[@]}" --out "$tmp/replay.mcap" --domain "$domain" 2> "$tmp/replay_rec.log" &
replay_rec=$!
pids+=("$replay_rec")
play_args=()
for t in "${inputs[@]}"; do play_args+=(--topic "$t"); done
"$canyon" play "$tmp/live.mcap" "${play_args[@]}" --pace 1 --wait-for-readers 1 --linger 120 --domain "$domain" -q &
play=$!
pids+=("$play")
"$canyon" rover --config "$tmp/replay.yaml" -q --wait-for-subscribers 1 --wait-timeout 30
kill -INT "$play" "$replay_rec"
wait "$play" || true
wait "$replay_rec" || { echo "FAIL: canyon record (replay): $(cat "$tmp/replay_rec.log")"; exit 1; }

solved=$(grep -v '^%' "$tmp/live.pos" | awk '$6 != 0' | wc -l)
[[ $solved -gt $((epochs * 9 / 10)) ]] || { echo "FAIL: the live rover solved only $solved of $epochs epochs"; exit 1; }
if ! cmp -s <(grep -v '^%' "$tmp/live.pos") <(grep -v '^%' "$tmp/replay.pos"); then
  echo "FAIL: the rover on the played session differs from the live rover:"
  diff <(grep -v '^%' "$tmp/live.pos") <(grep -v '^%' "$tmp/replay.pos") | head -5
  exit 1
fi
echo "play -> rover: the same $(grep -vc '^%' "$tmp/live.pos") solutions, byte for byte, as the live rover ($solved solved)"
node "$decoders/mcap_check.mjs" "$tmp/replay.mcap" "$tmp/live.pos" "$epochs" "${outputs[@]}"

# canyon process --session: the live session's rover inputs (canyon/observations, canyon/rtcm, canyon/vio,
# canyon/timesync) processed as files, with the causal time bridge of a live rover, give the live rover's solutions.
printf 'mode: fusion\nfusion: {timesync_mode: causal}\n' > "$tmp/process.yaml"
"$canyon" process --session "$tmp/live.mcap" --session-dir "$tmp/extracted" --config "$tmp/process.yaml" \
  --nav "$tmp/sim/nav.rnx" --out "$tmp/processed.pos" -q
if ! cmp -s <(grep -v '^%' "$tmp/live.pos") <(grep -v '^%' "$tmp/processed.pos"); then
  echo "FAIL: canyon process --session differs from the live rover:"
  diff <(grep -v '^%' "$tmp/live.pos") <(grep -v '^%' "$tmp/processed.pos") | head -5
  exit 1
fi
echo "canyon process --session live.mcap: the same $(grep -vc '^%' "$tmp/processed.pos") solutions as the live rover"
# An input given on the command line wins over the session's: rtk with the base's RINEX file equals rtk on the files.
"$canyon" process --session "$tmp/live.mcap" --mode rtk --base "$tmp/sim/base.obs" --nav "$tmp/sim/nav.rnx" \
  --out "$tmp/session_rtk.pos" -q
"$canyon" process --mode rtk --rover "$tmp/sim/rover.obs" --base "$tmp/sim/base.obs" --nav "$tmp/sim/nav.rnx" \
  --out "$tmp/files_rtk.pos" -q
cmp -s <(grep -v '^%' "$tmp/session_rtk.pos") <(grep -v '^%' "$tmp/files_rtk.pos") ||
  { echo "FAIL: canyon process --session --mode rtk --base BASE.obs differs from rtk on the files"; exit 1; }
echo "canyon process --session --mode rtk --base BASE.obs: the same solutions as rtk on the rover's and base's files"
rc=0
"$canyon" process --session "$tmp/replay.mcap" --config "$tmp/process.yaml" --out "$tmp/x.pos" > "$tmp/bad.log" 2>&1 || rc=$?
[[ $rc -ne 0 ]] && grep -qF "no rover observations (canyon/observations" "$tmp/bad.log" ||
  { echo "FAIL: canyon process --session of a session without the rover's epochs: exit $rc, $(cat "$tmp/bad.log")"; exit 1; }
echo "canyon process --session of a session without the rover's epochs: named"

# Bad input: a topic the session does not hold.
rc=0
"$canyon" play "$tmp/live.mcap" --topic canyon/float --domain "$domain" > "$tmp/bad.log" 2>&1 || rc=$?
[[ $rc -eq 2 ]] && grep -qF "topic 'canyon/float' (--topic) is not in the session" "$tmp/bad.log" ||
  { echo "FAIL: canyon play --topic canyon/float: exit $rc, $(cat "$tmp/bad.log")"; exit 1; }
echo "canyon play --topic of a topic the session does not hold: named"
