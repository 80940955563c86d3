#!/usr/bin/env bash
# Four processes on loopback DDS: canyon base (RINEX replay) -> canyon rover (six-stage threaded pipeline, base from
# DDS) -> canyon record (solutions to .pos) + canyon monitor (--json); a second canyon record keeps the RTCM stream
# (canyon/rtcm) so that canyon process can run on exactly the base observations the rover received. Checks that
# the recorded .pos records equal canyon process's (byte for byte, header lines aside: they name the programs) and
# that no solution was lost, and prints the monitor's last figures. urban-severe runs twice: the rover reading the
# VIO files, and the rover fed by a fifth process, canyon vio, publishing the VIO poses and time-sync pairs on DDS
# (compared with canyon process with fusion.timesync_mode causal, the mapping a live rover uses).
#
# Usage: tests/bench/rover_loopback.sh [instinct|urban-severe|both] [BUILD_DIR] [WORK_DIR]
#   env BASE_PACE (default 20: base replay speed; the rover follows the base), SIM_DURATION_S (urban-severe, 60),
#   DOMAIN (default: 150 + PID % 80).
# Exit 0 when every check passes, 1 otherwise, 77 (with a SKIP: line) when the shared data is missing and nothing
# failed: with both, urban-severe (generated) still runs, and the missing instinct run makes the whole a skip.
set -uo pipefail

which_runs="${1:-both}"
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${2:-${root}/build}"
work="${3:-/tmp/canyon_rover_loopback}"
data="${CANYON_SHARED_DATA_DIR:-${root}/../shared/data}"
base_pace="${BASE_PACE:-20}"
sim_duration="${SIM_DURATION_S:-60}"
domain="${DOMAIN:-$((150 + $$ % 80))}"
canyon="${build}/canyon"
profiles="${root}/config/dds/canyon_profiles.xml"
failures=0
skipped=""

header_position() {  # APPROX POSITION XYZ of a RINEX file as "X, Y, Z"
  awk '/APPROX POSITION XYZ/ { printf "%s, %s, %s", $1, $2, $3; exit }' "$1"
}

# run NAME MODE ROVER BASE NAV ESTIMATOR_EXTRA_YAML(file with estimator keys, indented, or "") [VIO_CSV TIMESYNC_CSV]
# With VIO_CSV, canyon vio publishes it on DDS and the rover takes its VIO from there (input.vio dds).
run() {
  local name="$1" mode="$2" rover="$3" base="$4" nav="$5" extra="$6" vio_csv="${7:-}" timesync_csv="${8:-}"
  local dir="${work}/${name}"
  rm -rf "${dir}" && mkdir -p "${dir}"
  local pos vio_source=file
  pos="$(header_position "${base}")"
  [[ -n "${vio_csv}" ]] && vio_source=dds
  {
    echo "station: {id: 1}"
    echo "input: {kind: rinex, source: file, path: ${base}, nav: [${nav}], pace: ${base_pace}}"
    echo "outputs:"
    echo "  dds: {enabled: true, domain: ${domain}, topic: canyon/rtcm, profiles: ${profiles}}"
    echo "  ntrip: {enabled: false}"
    echo "log: {progress_interval_s: 0}"
  } > "${dir}/base.yaml"
  {
    echo "estimator:"
    if [[ -n "${extra}" ]]; then sed 's/^/  /' "${extra}" | causal; else echo "  mode: ${mode}"; fi
    echo "  rover: ${rover}"
    echo "  nav: [${nav}]"
    # STREAM_BASE_POSITION=1: no base position given, the rover takes it from the RTCM 1005 of the stream.
    [[ "${STREAM_BASE_POSITION:-0}" == 1 ]] || echo "  base_position: [${pos}]"
    [[ -z "${vio_csv}" && -f "${dir}/../${name}.vio" ]] && cat "${dir}/../${name}.vio"
    echo "rover_id: ${name}"
    echo "input: {pace: 0, base: dds, base_wait_s: 5, vio: ${vio_source}, vio_wait_s: 5}"
    echo "pipeline: {threaded: true, queue_capacity: 64}"
    echo "dds: {domain: ${domain}, profiles: ${profiles}}"
  } > "${dir}/rover.yaml"

  "${canyon}" record canyon/solution --out "${dir}/recorded.pos" --domain "${domain}" 2> "${dir}/record.log" &
  local rec=$!
  "${canyon}" record canyon/rtcm --out "${dir}/base.rtcm3" --domain "${domain}" 2> "${dir}/record_rtcm.log" &
  local rec_rtcm=$!
  # The monitor also serves the live dashboard (--http 0: a free port, printed to its log); a poller keeps the last
  # /metrics page that shows a solution.
  "${canyon}" monitor --json --interval 1 --http 0 --domain "${domain}" > "${dir}/monitor.jsonl" \
    2> "${dir}/monitor.log" &
  local mon=$!
  poll_dashboard "${dir}" &
  local poller=$!
  local vio_pid=""
  if [[ -n "${vio_csv}" ]]; then
    "${canyon}" vio --vio "${vio_csv}" --timesync "${timesync_csv}" --pace 0 --wait-for-readers 1 --linger 120 \
      --domain "${domain}" --profiles "${profiles}" > "${dir}/vio.log" 2>&1 &
    vio_pid=$!
  fi
  "${canyon}" rover --config "${dir}/rover.yaml" --wait-for-subscribers 2 > "${dir}/rover.log" 2>&1 &
  local rov=$!
  local start end
  start=$(date +%s.%N)
  # The base starts once the rover's and the RTCM recorder's readers are matched.
  "${canyon}" base --config "${dir}/base.yaml" --wait-for-clients 2 -q > "${dir}/base.log" 2>&1
  local base_rc=$?
  wait "${rov}"
  local rover_rc=$?
  end=$(date +%s.%N)
  wait "${rec}" "${rec_rtcm}" "${mon}"
  local vio_rc=0
  if [[ -n "${vio_pid}" ]]; then
    wait "${vio_pid}"
    vio_rc=$?
  fi
  kill "${poller}" 2> /dev/null
  wait "${poller}" 2> /dev/null
  if ((base_rc != 0 || rover_rc != 0 || vio_rc != 0)); then
    echo "rover_loopback ${name}: FAIL: base exit ${base_rc}, rover exit ${rover_rc}, vio exit ${vio_rc} (logs in ${dir})"
    failures=$((failures + 1))
    return
  fi
  local process_yaml="${dir}/process.yaml"
  {
    if [[ -n "${extra}" ]]; then causal < "${extra}"; else echo "mode: ${mode}"; fi
    [[ -f "${dir}/../${name}.vio" ]] && sed 's/^  //' "${dir}/../${name}.vio"
  } > "${process_yaml}"
  local base_pos_args=(--base-pos "${pos// /}")
  [[ "${STREAM_BASE_POSITION:-0}" == 1 ]] && base_pos_args=()  # the .rtcm3's 1005, as the rover
  "${canyon}" process -q --config "${process_yaml}" --rover "${rover}" --base "${dir}/base.rtcm3" --nav "${nav}" \
    "${base_pos_args[@]}" --out "${dir}/process.pos" > "${dir}/process.log" 2>&1
  grep -v '^%' "${dir}/recorded.pos" > "${dir}/recorded.records"
  grep -v '^%' "${dir}/process.pos" > "${dir}/process.records"
  local n_rec n_proc lost
  n_rec=$(wc -l < "${dir}/recorded.records")
  n_proc=$(wc -l < "${dir}/process.records")
  lost=$(tail -n 1 "${dir}/monitor.jsonl" | sed -n 's/.*"lost_solutions":\([0-9]*\).*/\1/p')
  if [[ -n "${vio_csv}" ]]; then
    echo "rover_loopback ${name}: rover: $(grep -o 'VIO over DDS: .*' "${dir}/rover.log")"
  fi
  if cmp -s "${dir}/recorded.records" "${dir}/process.records" && ((n_rec > 0)) && [[ "${lost}" == "0" ]]; then
    echo "rover_loopback ${name}: PASS: ${n_rec} solutions recorded = canyon process (byte for byte), 0 lost," \
      "$(awk -v s="${start}" -v e="${end}" 'BEGIN { printf "%.1f", e - s }') s wall (base pace ${base_pace})"
  else
    echo "rover_loopback ${name}: FAIL: recorded ${n_rec} records, canyon process ${n_proc}, lost '${lost}'" \
      "(diff ${dir}/recorded.records ${dir}/process.records)"
    failures=$((failures + 1))
  fi
  echo "rover_loopback ${name}: monitor: $(tail -n 1 "${dir}/monitor.jsonl")"
  if grep -q '^canyon_solution_status' "${dir}/dashboard_metrics.txt" 2> /dev/null; then
    echo "rover_loopback ${name}: PASS: canyon monitor --http served /metrics with the rover's solutions:" \
      "$(grep -c '^canyon_' "${dir}/dashboard_metrics.txt") samples"
  else
    echo "rover_loopback ${name}: FAIL: canyon monitor --http never served a /metrics page with a solution" \
      "(${dir}/monitor.log)"
    failures=$((failures + 1))
  fi
}

# causal: stdin to stdout, with fusion.timesync_mode causal when CAUSAL=1.
causal() {
  if [[ "${CAUSAL:-0}" == 1 ]]; then sed 's/timesync_mode: whole_file/timesync_mode: causal/'; else cat; fi
}

# poll_dashboard DIR: while the monitor runs, fetch its /metrics every 0.5 s into DIR/dashboard_metrics.txt (the
# last page that has a solution).
poll_dashboard() {
  local dir=$1 port=""
  for _ in $(seq 600); do
    [[ -z "${port}" ]] && port=$(sed -n 's|.*dashboard on http://[^:]*:\([0-9]*\)/.*|\1|p' "${dir}/monitor.log" 2> /dev/null)
    if [[ -n "${port}" ]]; then
      python3 - "${port}" "${dir}/dashboard_metrics.txt" << 'PY' 2> /dev/null
import sys, urllib.request
text = urllib.request.urlopen("http://127.0.0.1:%s/metrics" % sys.argv[1], timeout=2).read().decode()
if "canyon_solution_status" in text:
    open(sys.argv[2], "w").write(text)
PY
    fi
    sleep 0.5
  done
}

mkdir -p "${work}"
if [[ "${which_runs}" == instinct || "${which_runs}" == both ]]; then
  inst="${data}/instinct-spirent-rtk-sim"
  if [[ ! -d "${inst}" ]]; then
    skipped="instinct run not made: shared data not found at ${inst}"
    echo "rover_loopback instinct: ${skipped}"
  else
    # The rover is not given the base position: it takes it from the base's RTCM 1005.
    STREAM_BASE_POSITION=1 run instinct rtk "${inst}/iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs" \
      "${inst}/iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs" "${inst}/RINEX_GN_Spirent.23N" \
      "${root}/config/rtk.yaml"
  fi
fi
if [[ "${which_runs}" == urban-severe || "${which_runs}" == both ]]; then
  sim="${work}/urban-severe-sim"
  rm -rf "${sim}"
  if ! "${canyon}" simulate -q --scenario urban-severe --seed 1 --duration "${sim_duration}" --out "${sim}" \
    > "${work}/simulate.log" 2>&1; then
    echo "rover_loopback urban-severe: FAIL: canyon simulate (see ${work}/simulate.log)"
    failures=$((failures + 1))
  else
    printf '  vio: %s\n  timesync: %s\n' "${sim}/vio.csv" "${sim}/timesync.csv" > "${work}/urban-severe.vio"
    run urban-severe fusion "${sim}/rover.obs" "${sim}/base.obs" "${sim}/nav.rnx" "${root}/config/fusion.yaml"
    # The same with the VIO over DDS: canyon process then maps the VIO as the live rover does (causal).
    printf '  vio: %s\n  timesync: %s\n' "${sim}/vio.csv" "${sim}/timesync.csv" > "${work}/urban-severe-vio-dds.vio"
    CAUSAL=1 run urban-severe-vio-dds fusion "${sim}/rover.obs" "${sim}/base.obs" "${sim}/nav.rnx" \
      "${root}/config/fusion.yaml" "${sim}/vio.csv" "${sim}/timesync.csv"
  fi
fi
if ((failures > 0)); then exit 1; fi
if [[ -n "${skipped}" ]]; then
  echo "SKIP: ${skipped}"
  exit 77
fi
exit 0
