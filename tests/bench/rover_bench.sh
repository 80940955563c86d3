#!/usr/bin/env bash
# Measurements of the real-time rover pipeline (issue 7), each printing its figures:
#   throughput  fusion on a generated urban-severe scenario, as fast as possible: canyon process (bridge-ahead, the
#               default), canyon process --pipeline threaded and canyon rover (threaded, DDS publishing) against
#               RTKLIB rnx2rtkp on the same GNSS files
#   latency     5 Hz at real-time pace: in-process end to end (canyon rover, base from file) and base in another
#               process over DDS to the solution at a subscriber in a third process (canyon monitor)
#   scale       one base, N rovers (16) and M subscribers (4) at 5 Hz for D seconds: lost solutions, latency
#   memory      the rover's resident memory, sampled every 0.5 s, over a long replay
# Usage: tests/bench/rover_bench.sh {throughput|latency|scale|memory|all} [BUILD_DIR] [WORK_DIR]
#   env: THROUGHPUT_S (600 s of data), LATENCY_S (120), SCALE_S (120), ROVERS (16), SUBSCRIBERS (4), MEMORY_S (1800),
#        MEMORY_PACE (0: as fast as possible), DOMAIN (default 150 + PID % 80), PIPELINE_THREADED (true; false runs
#        the rovers' stages on one thread), PIPELINE_AFFINITY (the rovers' pipeline.cpu_affinity, e.g. "{ingest: [0],
#        time_bridge: [0], alignment: [1], prediction: [1], update: [1], ambiguity: [1]}"; default: none)
set -uo pipefail

what="${1:-all}"
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${2:-${root}/build}"
work="${3:-/tmp/canyon_rover_bench}"
canyon="${build}/canyon"
profiles="${root}/config/dds/canyon_profiles.xml"
domain="${DOMAIN:-$((150 + $$ % 80))}"
mkdir -p "${work}"

# simulate NAME DURATION_S BASE_RATE_HZ: urban-severe with VIO, base at the given rate.
simulate() {
  local dir="${work}/$1"
  if [[ -f "${dir}/rover.obs" && -f "${dir}/.done_$2_$3" ]]; then return 0; fi
  rm -rf "${dir}" && mkdir -p "${dir}"
  # The scenario's base rate is the first 'rate_hz' after 'base:'.
  awk -v r="$3" '/^base:/ { b = 1 } b && /^  rate_hz:/ { sub(/rate_hz: *[0-9.]+/, "rate_hz: " r); b = 0 } { print }' \
    "${root}/config/scenarios/urban-severe.yaml" > "${dir}/scenario.yaml"
  "${canyon}" simulate -q --scenario "${dir}/scenario.yaml" --seed 1 --duration "$2" --out "${dir}" \
    > "${dir}/simulate.log" 2>&1 || {
    echo "simulate failed: ${dir}/simulate.log"
    exit 1
  }
  touch "${dir}/.done_$2_$3"
}

header_position() { awk '/APPROX POSITION XYZ/ { printf "%s, %s, %s", $1, $2, $3; exit }' "$1"; }

# rover_yaml DIR SIM BASE(file|dds) PACE ROVER_ID > rover.yaml
rover_yaml() {
  local sim="$2"
  echo "estimator:"
  sed 's/^/  /' "${root}/config/fusion.yaml"
  echo "  rover: ${sim}/rover.obs"
  echo "  base: ${sim}/base.obs"
  echo "  nav: [${sim}/nav.rnx]"
  echo "  vio: ${sim}/vio.csv"
  echo "  timesync: ${sim}/timesync.csv"
  echo "  base_position: [$(header_position "${sim}/base.obs")]"
  echo "rover_id: $5"
  echo "input: {pace: $4, base: $3, base_wait_s: 5}"
  echo "pipeline: {threaded: ${PIPELINE_THREADED:-true}, queue_capacity: 64${PIPELINE_AFFINITY:+, cpu_affinity: ${PIPELINE_AFFINITY}}}"
  echo "dds: {domain: ${domain}, profiles: ${profiles}}"
}

base_yaml() {  # SIM PACE
  echo "station: {id: 7}"
  echo "input: {kind: rinex, source: file, path: $1/base.obs, nav: [$1/nav.rnx], pace: $2}"
  echo "outputs:"
  echo "  dds: {enabled: true, domain: ${domain}, topic: canyon/rtcm, profiles: ${profiles}}"
  echo "  ntrip: {enabled: false}"
  echo "log: {progress_interval_s: 0}"
}

# percentiles KEY FILE: "p50 / p95 / p99 / max us (count)" of a monitor JSON line's KEY.
percentiles() {
  python3 -c '
import json, sys
d = json.loads(open(sys.argv[2]).read().strip().splitlines()[-1])
p = d[sys.argv[1]]
print("p50 %.0f / p95 %.0f / p99 %.0f / max %.0f us (%d samples)" % (p["p50_us"], p["p95_us"], p["p99_us"], p["max_us"], p["count"]))
' "$1" "$2"
}

# allowed_cpus: the CPUs this shell may run on, space-separated ("0-2,5" -> "0 1 2 5").
allowed_cpus() {
  taskset -pc $$ | sed 's/.*: //; s/,/ /g' | awk '{ for (i = 1; i <= NF; ++i) {
    n = split($i, r, "-"); if (n == 1) print r[1]; else for (c = r[1]; c <= r[2]; ++c) print c } }' | tr '\n' ' '
}

# timed_rover YAML LOG: canyon rover on YAML, its output to LOG; sets rover_wall_s (the whole process, start-up
# included) and rover_pipeline ("N epochs/s in its pipeline (S s)", from the rover's summary line).
timed_rover() {
  local t0 t1
  t0=$(date +%s.%N)
  "${canyon}" rover --config "$1" > "$2" 2>&1
  t1=$(date +%s.%N)
  rover_pipeline=$(sed -n 's/.* epochs, .* in \([0-9.]*\) s (\([0-9]*\) epochs\/s).*/\2 epochs\/s in its pipeline (\1 s)/p' "$2")
  rover_wall_s=$(awk -v a="${t0}" -v b="${t1}" 'BEGIN { print b - a }')
}

throughput() {
  local seconds="${THROUGHPUT_S:-600}"
  simulate thr "${seconds}" 1
  local sim="${work}/thr"
  local epochs
  epochs=$(grep -c '^>' "${sim}/rover.obs")
  local t0 t1
  t0=$(date +%s.%N)
  "${canyon}" process --config "${root}/config/fusion.yaml" --rover "${sim}/rover.obs" --base "${sim}/base.obs" \
    --nav "${sim}/nav.rnx" --vio "${sim}/vio.csv" --timesync "${sim}/timesync.csv" --out "${sim}/threaded.pos" \
    --pipeline threaded -q
  t1=$(date +%s.%N)
  local process_s
  process_s=$(awk -v a="${t0}" -v b="${t1}" 'BEGIN { print b - a }')
  # The default layout: ingest and the time bridge on a second thread, ahead of the estimator stages (bridge-ahead).
  t0=$(date +%s.%N)
  "${canyon}" process --config "${root}/config/fusion.yaml" --rover "${sim}/rover.obs" --base "${sim}/base.obs" \
    --nav "${sim}/nav.rnx" --vio "${sim}/vio.csv" --timesync "${sim}/timesync.csv" --out "${sim}/ahead.pos" -q
  t1=$(date +%s.%N)
  local ahead_s
  ahead_s=$(awk -v a="${t0}" -v b="${t1}" 'BEGIN { print b - a }')
  rover_yaml "${work}" "${sim}" file 0 thr > "${sim}/rover.yaml"
  timed_rover "${sim}/rover.yaml" "${sim}/rover.log"
  local rover_run="${rover_pipeline}" rover_s="${rover_wall_s}"
  # The same rover with its stage threads pinned: ingest and the time bridge on one CPU, the estimator's four stages
  # on another (pipeline.cpu_affinity), when this process may use two.
  local cpus pinned_run="" pinned_s=""
  read -r -a cpus <<< "$(allowed_cpus)"
  if ((${#cpus[@]} >= 2)); then
    local a="${cpus[0]}" b="${cpus[1]}"
    PIPELINE_AFFINITY="{ingest: [${a}], time_bridge: [${a}], alignment: [${b}], prediction: [${b}], update: [${b}], ambiguity: [${b}]}" \
      rover_yaml "${work}" "${sim}" file 0 thr > "${sim}/rover_pinned.yaml"
    timed_rover "${sim}/rover_pinned.yaml" "${sim}/rover_pinned.log"
    pinned_run="${rover_pipeline}" pinned_s="${rover_wall_s}"
  fi
  t0=$(date +%s.%N)
  rnx2rtkp -k "${root}/config/rtklib/sim.conf" -o "${sim}/rtklib.pos" "${sim}/rover.obs" "${sim}/base.obs" \
    "${sim}/nav.rnx" 2> /dev/null
  t1=$(date +%s.%N)
  local rtklib_s
  rtklib_s=$(awk -v a="${t0}" -v b="${t1}" 'BEGIN { print b - a }')
  awk -v n="${epochs}" -v p="${process_s}" -v a="${ahead_s}" -v r="${rover_s}" -v k="${rtklib_s}" -v rr="${rover_run}" \
    -v ps="${pinned_s}" -v pr="${pinned_run}" 'BEGIN {
    printf "throughput: %d epochs (urban-severe, %s s of 5 Hz data, fusion)\n", n, n / 5
    printf "  canyon process (bridge-ahead, two threads): %.2f s, %.0f epochs/s, %.1fx rnx2rtkp\n", a, n / a, k / a
    printf "  canyon process --pipeline threaded: %.2f s, %.0f epochs/s\n", p, n / p
    printf "  canyon rover (threaded, DDS out, pace 0): %.2f s with start-up, %.0f epochs/s; %s\n", r, n / r, rr
    if (ps != "") printf "  canyon rover, stage threads pinned (pipeline.cpu_affinity): %.2f s with start-up, %.0f epochs/s; %s\n", ps, n / ps, pr
    printf "  rnx2rtkp (RTK only, config/rtklib/sim.conf): %.2f s, %.0f epochs/s; canyon rover %.1fx, process %.1fx\n",
      k, n / k, k / r, k / p }'
  throughput_instinct
}

# best_of N CMD...: the shortest wall time of N runs (s); output and errors discarded.
best_of() {
  local n="$1" best=""
  shift
  for ((i = 0; i < n; ++i)); do
    local t0 t1
    t0=$(date +%s.%N)
    "$@" > /dev/null 2>&1
    t1=$(date +%s.%N)
    best=$(awk -v a="${t0}" -v b="${t1}" -v m="${best}" 'BEGIN { d = b - a; print (m == "" || d < m) ? d : m }')
  done
  echo "${best}"
}

# canyon process (rtk, threaded pipeline) against rnx2rtkp on instinct-spirent-rtk-sim, best of 5 each.
throughput_instinct() {
  local d="${CANYON_SHARED_DATA_DIR:-${root}/../shared/data}/instinct-spirent-rtk-sim"
  if [[ ! -d "${d}" ]]; then
    echo "  instinct-spirent-rtk-sim: not measured: shared dataset not found at ${d}"
    return 0
  fi
  local rover="${d}/iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs" base="${d}/iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs"
  local nav="${d}/RINEX_GN_Spirent.23N" out="${work}/instinct"
  mkdir -p "${out}"
  local c k
  c=$(best_of 5 "${canyon}" process -q --config "${root}/config/rtk.yaml" --rover "${rover}" --base "${base}" \
    --nav "${nav}" --out "${out}/canyon.pos" --pipeline threaded)
  k=$(best_of 5 rnx2rtkp -k "${root}/config/rtklib/sim.conf" -o "${out}/rtklib.pos" "${rover}" "${base}" "${nav}")
  awk -v c="${c}" -v k="${k}" 'BEGIN { printf "  instinct-spirent-rtk-sim, 601 epochs, rtk, best of 5: canyon process --pipeline threaded %.3f s (%.0f epochs/s), rnx2rtkp %.3f s: %.1fx\n", c, 601 / c, k, k / c }'
}

latency() {
  local seconds="${LATENCY_S:-120}"
  simulate lat "$((seconds + 10))" 5
  local sim="${work}/lat"
  # In process: base from the file, rover at real-time pace (5 Hz).
  rover_yaml "${work}" "${sim}" file 1 lat > "${sim}/rover_file.yaml"
  "${canyon}" monitor --json --interval 1 --domain "${domain}" > "${sim}/monitor_file.jsonl" 2> /dev/null &
  local mon=$!
  timeout $((seconds + 30)) "${canyon}" rover --config "${sim}/rover_file.yaml" --wait-for-subscribers 1 -q \
    > "${sim}/rover_file.log" 2>&1 &
  local rov=$!
  sleep "${seconds}"
  kill -INT "${rov}" 2> /dev/null
  wait "${rov}" "${mon}"
  echo "latency, 5 Hz real-time pace, fusion, ${seconds} s:"
  echo "  in process (arrival at ingest -> ambiguity stage exit): $(percentiles end_to_end "${sim}/monitor_file.jsonl")"
  # Across processes: base (5 Hz, real-time pace) -> DDS -> rover (follows the base) -> DDS -> monitor.
  rover_yaml "${work}" "${sim}" dds 0 lat > "${sim}/rover_dds.yaml"
  base_yaml "${sim}" 1 > "${sim}/base.yaml"
  "${canyon}" monitor --json --interval 1 --domain "${domain}" > "${sim}/monitor_dds.jsonl" 2> /dev/null &
  mon=$!
  "${canyon}" rover --config "${sim}/rover_dds.yaml" --wait-for-subscribers 1 -q > "${sim}/rover_dds.log" 2>&1 &
  rov=$!
  timeout $((seconds + 30)) "${canyon}" base --config "${sim}/base.yaml" --wait-for-clients 1 -q \
    > "${sim}/base.log" 2>&1 &
  local bas=$!
  sleep "${seconds}"
  kill -INT "${bas}" 2> /dev/null
  wait "${bas}"
  kill -INT "${rov}" 2> /dev/null
  wait "${rov}" "${mon}"
  echo "  base process -> rover process -> monitor process (base's send of the epoch's last RTCM frame -> solution" \
    "received): $(percentiles base_to_solution "${sim}/monitor_dds.jsonl")"
  echo "  of which in the rover (epoch complete -> ambiguity exit): $(percentiles end_to_end "${sim}/monitor_dds.jsonl")"
}

scale() {
  local seconds="${SCALE_S:-120}" rovers="${ROVERS:-16}" subs="${SUBSCRIBERS:-4}"
  simulate lat "$((seconds + 10))" 5
  local sim="${work}/lat" dir="${work}/scale"
  rm -rf "${dir}" && mkdir -p "${dir}"
  base_yaml "${sim}" 1 > "${dir}/base.yaml"
  local pids=() mons=()
  for ((s = 0; s < subs; ++s)); do
    "${canyon}" monitor --json --interval 5 --domain "${domain}" > "${dir}/monitor${s}.jsonl" 2> /dev/null &
    mons+=($!)
  done
  for ((r = 0; r < rovers; ++r)); do
    rover_yaml "${work}" "${sim}" dds 0 "rover${r}" > "${dir}/rover${r}.yaml"
    "${canyon}" rover --config "${dir}/rover${r}.yaml" --wait-for-subscribers "${subs}" -q > "${dir}/rover${r}.log" 2>&1 &
    pids+=($!)
  done
  timeout $((seconds + 60)) "${canyon}" base --config "${dir}/base.yaml" --wait-for-clients "${rovers}" \
    --wait-timeout 60 -q > "${dir}/base.log" 2>&1 &
  local bas=$!
  sleep "${seconds}"
  kill -INT "${bas}" 2> /dev/null
  wait "${bas}"
  for p in "${pids[@]}"; do kill -INT "${p}" 2> /dev/null; done
  for p in "${pids[@]}"; do wait "${p}"; done
  for p in "${mons[@]}"; do wait "${p}"; done
  echo "scale: 1 base, ${rovers} rovers (fusion), ${subs} subscribers, 5 Hz, ${seconds} s:"
  for ((s = 0; s < subs; ++s)); do
    python3 -c '
import json, sys
d = json.loads(open(sys.argv[1]).read().strip().splitlines()[-1])
b = d["base_to_solution"]; e = d["end_to_end"]
print("  subscriber %s: %d rovers, %d solutions, %d lost; base->solution p50 %.0f p95 %.0f p99 %.0f max %.0f us; in rover p50 %.0f p99 %.0f us"
      % (sys.argv[2], d["rovers"], d["solutions"], d["lost_solutions"], b["p50_us"], b["p95_us"], b["p99_us"], b["max_us"], e["p50_us"], e["p99_us"]))
' "${dir}/monitor${s}.jsonl" "${s}"
  done
}

memory() {
  local seconds="${MEMORY_S:-1800}" pace="${MEMORY_PACE:-0}"
  simulate mem "${seconds}" 1
  local sim="${work}/mem"
  rover_yaml "${work}" "${sim}" file "${pace}" mem > "${sim}/rover.yaml"
  "${canyon}" rover --config "${sim}/rover.yaml" -q > "${sim}/rover.log" 2>&1 &
  local rov=$!
  : > "${sim}/rss.txt"
  while kill -0 "${rov}" 2> /dev/null; do
    local pid
    pid=$(pgrep -P "${rov}" canyon-rover || echo "${rov}")
    awk '/VmRSS/ { print $2 }' "/proc/${pid}/status" 2> /dev/null >> "${sim}/rss.txt"
    sleep 0.5
  done
  wait "${rov}"
  awk -v s="${seconds}" 'NF { v[n++] = $1 } END {
    if (n == 0) { print "memory: no samples"; exit }
    min = v[0]; max = v[0]; for (i = 0; i < n; ++i) { if (v[i] < min) min = v[i]; if (v[i] > max) max = v[i] }
    q = int(n / 4); if (q < 1) q = 1
    printf "memory: rover RSS over a %d s replay (fusion, %d samples every 0.5 s): min %.1f MB, max %.1f MB; first quarter max %.1f MB, last quarter max %.1f MB\n",
      s, n, min / 1024, max / 1024, fq(v, 0, q) / 1024, fq(v, n - q, n) / 1024 }
    function fq(a, lo, hi,   m, i) { m = a[lo]; for (i = lo; i < hi; ++i) if (a[i] > m) m = a[i]; return m }' "${sim}/rss.txt"
}

case "${what}" in
  throughput) throughput ;;
  latency) latency ;;
  scale) scale ;;
  memory) memory ;;
  all) throughput && latency && scale && memory ;;
  *)
    echo "usage: $0 {throughput|latency|scale|memory|all} [BUILD_DIR] [WORK_DIR]" >&2
    exit 2
    ;;
esac
