#!/usr/bin/env bash
# canyon vio and canyon rover (input.vio dds) with each shipped deployment profile, on loopback: for every
# deploy/dds/*.xml (loaded on top of config/dds/canyon_profiles.xml) canyon vio publishes a simulated urban-severe run
# (20 s) and canyon rover, fed its VIO over DDS, solves it, with canyon record on the solution topic. Checks that the
# three exit 0, that the rover received every VIO pose and time-sync pair the node published, and that solutions
# were recorded. The deployment files name the hosts of deploy/netns/twohost.sh (10.77.0.1, 10.77.0.2): the test
# runs loopback copies with 127.0.0.1 instead, as a deployment puts its own addresses in; for the discovery-server
# profile it starts a fast-discovery-server (id 0) on a free port of 127.0.0.1 and points the copy at it.
#
# Usage: tests/bench/deploy_profiles.sh [BUILD_DIR] [WORK_DIR]     env DOMAIN (default: 60 + PID % 80)
# Exit 0 when every profile passes, 1 otherwise, 77 without fast-discovery-server.
set -uo pipefail

root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${1:-${root}/build}"
work="${2:-/tmp/canyon_deploy_profiles}"
domain="${DOMAIN:-$((60 + $$ % 80))}"
canyon="${build}/canyon"
failures=0
server_pid=""

cleanup() {
  [[ -n "${server_pid}" ]] && kill "${server_pid}" 2> /dev/null && wait "${server_pid}" 2> /dev/null
}
trap cleanup EXIT

command -v fast-discovery-server > /dev/null || {
  echo "deploy_profiles: fast-discovery-server not found (Debian fastdds-tools)"
  exit 77
}

free_udp_port() {
  python3 -c 'import socket; s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

rm -rf "${work}" && mkdir -p "${work}"
sim="${work}/sim"
if ! "${canyon}" simulate -q --scenario urban-severe --seed 1 --duration 20 --out "${sim}" > "${work}/simulate.log" 2>&1; then
  echo "deploy_profiles: FAIL: canyon simulate (see ${work}/simulate.log)"
  exit 1
fi
poses=$(($(wc -l < "${sim}/vio.csv") - 1))
pairs=$(($(wc -l < "${sim}/timesync.csv") - 1))

# run NAME PROFILE: canyon vio -> canyon rover (input.vio dds) -> canyon record, all on PROFILE.
run() {
  local name="$1" profile="$2"
  local dir="${work}/${name}"
  mkdir -p "${dir}"
  {
    echo "estimator:"
    sed 's/^/  /' "${root}/config/fusion.yaml"
    echo "  rover: ${sim}/rover.obs"
    echo "  base: ${sim}/base.obs"
    echo "  nav: [${sim}/nav.rnx]"
    echo "rover_id: ${name}"
    echo "input: {pace: 5, base: file, vio: dds, vio_wait_s: 5}"
    echo "dds: {domain: ${domain}, profiles: ${profile}}"
  } > "${dir}/rover.yaml"
  "${canyon}" vio --vio "${sim}/vio.csv" --timesync "${sim}/timesync.csv" --pace 0 --wait-for-readers 1 --linger 30 \
    --domain "${domain}" --profiles "${profile}" > "${dir}/vio.log" 2>&1 &
  local vio=$!
  "${canyon}" record canyon/solution --out "${dir}/recorded.csv" --domain "${domain}" --profiles "${profile}" \
    --duration 60 2> "${dir}/record.log" &
  local rec=$!
  timeout 90 "${canyon}" rover --config "${dir}/rover.yaml" --wait-for-subscribers 1 > "${dir}/rover.log" 2>&1
  local rover_rc=$?
  wait "${vio}"
  local vio_rc=$?
  wait "${rec}"
  local rec_rc=$?
  local got solutions
  got=$(sed -n 's/.*VIO over DDS: \([0-9]*\) poses and \([0-9]*\) time-sync pairs received.*/\1 \2/p' "${dir}/rover.log")
  solutions=$(($(wc -l < "${dir}/recorded.csv" 2> /dev/null || echo 1) - 1))
  if ((rover_rc != 0 || vio_rc != 0 || rec_rc != 0)); then
    echo "deploy_profiles ${name}: FAIL: rover exit ${rover_rc}, vio exit ${vio_rc}, record exit ${rec_rc} (logs in ${dir})"
    failures=$((failures + 1))
  elif [[ "${got}" != "${poses} ${pairs}" ]]; then
    echo "deploy_profiles ${name}: FAIL: the rover received '${got}' VIO poses and pairs, canyon vio published" \
      "${poses} ${pairs} (logs in ${dir})"
    failures=$((failures + 1))
  elif ((solutions <= 0)); then
    echo "deploy_profiles ${name}: FAIL: no solution recorded (logs in ${dir})"
    failures=$((failures + 1))
  else
    echo "deploy_profiles ${name}: PASS: the rover received all ${poses} VIO poses and ${pairs} time-sync pairs," \
      "${solutions} solutions recorded"
  fi
  domain=$((domain + 1))
}

for file in "${root}"/deploy/dds/*.xml; do
  name="$(basename "${file}" .xml)"
  profile="${work}/${name}.xml"
  sed 's/10\.77\.0\.[0-9]*/127.0.0.1/g' "${file}" > "${profile}"
  if grep -q '<discoveryProtocol>CLIENT</discoveryProtocol>' "${profile}"; then
    port="$(free_udp_port)"
    sed -i "s#<port>11811</port>#<port>${port}</port>#" "${profile}"
    fast-discovery-server -i 0 -l 127.0.0.1 -p "${port}" > "${work}/${name}.server.log" 2>&1 &
    server_pid=$!
    sleep 0.5
  fi
  run "${name}" "${profile}"
  cleanup
  server_pid=""
done
exit $((failures > 0 ? 1 : 0))
