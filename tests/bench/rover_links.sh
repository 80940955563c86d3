#!/usr/bin/env bash
# canyon rover on real links, each peer a real program:
#  base-canyon   canyon base (RINEX replay of instinct-spirent-rtk-sim) serves NTRIP and TCP; two rovers take their base
#                from it (input.base ntrip, tcp); a canyon record of the base's DDS topic keeps the same RTCM stream.
#                Both .pos equal canyon process on the recorded stream, byte for byte (header lines aside). A third
#                rover with a wrong NTRIP password gets the 401 reported (password not shown) and goes on.
#  base-str2str  RTKLIB str2str serves canyon convert's RTCM 3 of the base file as tcpsvr:// and as NTRIP caster
#                (ntripc://); both rovers equal canyon process on that RTCM 3 file, byte for byte.
#  ubx           the u-blox M8P rover log of m8p-galway-20181004 (input.rover ubx) from the file, over TCP from
#                str2str tcpsvr:// and over a serial line (a pseudo-terminal): the .pos are equal byte for byte;
#                against canyon process on canyon convert's RINEX of the same log the positions agree within
#                kMaxUbxRinexDiffM (RINEX rounds pseudoranges to 1 mm, phases to 0.001 cycle and time tags to
#                0.1 us) with the same statuses. Also reported: the rover with the SFRBX ephemerides only (no
#                navigation file), threaded = sequential.
#  bad           a refused rover link, a refused base link, a receiver link that dies mid-log, a truncated log,
#                corrupt RTCM frames and SIGINT: each ends (or goes on) with a message naming the link, never hangs.
#
# Usage: tests/bench/rover_links.sh [BUILD_DIR] [WORK_DIR] [PARTS (default: base-canyon base-str2str ubx bad)]
#   env BASE_PACE (default 50: canyon base replay speed), DOMAIN (default: 150 + PID % 80).
# Exit 0 when every check passes, 1 otherwise, 77 (with a SKIP: line) when the shared data or RTKLIB's str2str is
# missing.
set -uo pipefail

root="$(cd "$(dirname "$0")/../.." && pwd)"
build="$(cd "${1:-${root}/build}" && pwd)"
work="${2:-/tmp/canyon_rover_links}"
mkdir -p "${work}" && work="$(cd "${work}" && pwd)"
parts="${3:-base-canyon base-str2str ubx bad}"
data="${CANYON_SHARED_DATA_DIR:-${root}/../shared/data}"
base_pace="${BASE_PACE:-50}"
domain="${DOMAIN:-$((150 + $$ % 80))}"
canyon="${build}/canyon"
profiles="${root}/config/dds/canyon_profiles.xml"
kMaxUbxRinexDiffM=0.005
failures=0

inst="${data}/instinct-spirent-rtk-sim"
inst_rover="${inst}/iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs"
inst_base="${inst}/iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs"
inst_nav="${inst}/RINEX_GN_Spirent.23N"
m8p="${data}/m8p-galway-20181004"
m8p_rover_ubx="${m8p}/20181004_rover-20181004-1532.ubx.gz"
m8p_base="${m8p}/rinex/20181004_base-20181004-1452.obs"
if [[ ! -d "${inst}" || ! -d "${m8p}" ]]; then
  echo "SKIP: rover_links: shared data not found at ${data} (instinct-spirent-rtk-sim, m8p-galway-20181004)"
  exit 77
fi
if ! command -v str2str > /dev/null; then
  echo "SKIP: rover_links: RTKLIB's str2str not installed (scripts/setup.sh installs rtklib)"
  exit 77
fi

pass() { echo "rover_links $1: PASS: ${*:2}"; }
fail() {
  echo "rover_links $1: FAIL: ${*:2}"
  failures=$((failures + 1))
}
header_position() { awk '/APPROX POSITION XYZ/ { printf "%s, %s, %s", $1, $2, $3; exit }' "$1"; }
free_port() { python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
records() { grep -v '^%' "$1"; }
same_records() { [[ -s "$1" && -s "$2" ]] && cmp -s <(records "$1") <(records "$2"); }
# established_on PORT: TCP connections established to a local port
established_on() { ss -Htn state established "( sport = :$1 )" 2> /dev/null | wc -l; }
# wait_clients PORT N: until N clients are connected to PORT (at most 20 s)
wait_clients() {
  for _ in $(seq 200); do
    (($(established_on "$1") >= $2)) && return 0
    sleep 0.1
  done
  return 1
}
# paced_cat FILE BYTES_PER_S: FILE to stdout at about that rate
paced_cat() {
  python3 - "$1" "$2" << 'PY'
import sys, time
data, rate, chunk = open(sys.argv[1], "rb").read(), float(sys.argv[2]), 4096
for i in range(0, len(data), chunk):
    sys.stdout.buffer.write(data[i : i + chunk])
    sys.stdout.flush()
    time.sleep(chunk / rate)
PY
}
# compare_pos A B: "max horizontal H m, max vertical V m, statuses differing S, records NA NB" (matched by time)
compare_pos() {
  awk 'FNR == 1 { f++ } /^%/ { next }
    f == 1 { k = $1 " " $2; lat[k] = $3; lon[k] = $4; h[k] = $5; q[k] = $6; na++; next }
    { nb++; k = $1 " " $2; if (!(k in lat)) { unmatched++; next }
      dn = ($3 - lat[k]) * 111320; de = ($4 - lon[k]) * 111320 * cos(lat[k] * 3.14159265 / 180); du = $5 - h[k]
      d = sqrt(dn * dn + de * de); if (d > mh) mh = d; if (du < 0) du = -du; if (du > mv) mv = du
      if ($6 != q[k]) dq++ }
    END { printf "%.4f %.4f %d %d %d %d\n", mh, mv, dq + 0, na, nb, unmatched + 0 }' "$1" "$2"
}
# rover_yaml NAME ESTIMATOR_EXTRA INPUT_FLOW: writes NAME.yaml for canyon rover
rover_yaml() {
  {
    echo "estimator:"
    echo "$2"
    echo "rover_id: $1"
    echo "input: {$3}"
    echo "dds: {domain: ${domain}, profiles: ${profiles}}"
  } > "$1.yaml"
}

inst_estimator() {
  sed -e '/^ *#/d' -e 's/^/  /' "${root}/config/rtk.yaml"
  echo "  rover: ${inst_rover}"
  echo "  nav: [${inst_nav}]"
  echo "  base_position: [$(header_position "${inst_base}")]"
}

# Two rovers (ntrip, tcp) against the RTCM 3 in ${dir}/base.rtcm3 through canyon process.
check_two_rovers() {
  local part=$1 dir=$2
  local pos
  pos="$(header_position "${inst_base}")"
  "${canyon}" process -q --config "${root}/config/rtk.yaml" --rover "${inst_rover}" --base "${dir}/base.rtcm3" \
    --nav "${inst_nav}" --base-pos "${pos// /}" --out "${dir}/process.pos" > "${dir}/process.log" 2>&1
  for k in ntrip tcp; do
    if ((${rc[$k]} != 0)); then
      fail "${part}" "rover ${k} exit ${rc[$k]} (${dir}/rover_${k}.log)"
    elif same_records "${dir}/${k}.pos" "${dir}/process.pos"; then
      pass "${part}" "rover base over ${k}: $(records "${dir}/${k}.pos" | wc -l) solutions = canyon process on the" \
        "same RTCM 3 (byte for byte), $(records "${dir}/${k}.pos" | awk '$6 == 1' | wc -l) fixed"
    else
      fail "${part}" "rover base over ${k} differs from canyon process (diff ${dir}/${k}.pos ${dir}/process.pos)"
    fi
  done
}

declare -A rc

part_base_canyon() {
  local dir="${work}/base-canyon"
  if ! { rm -rf "${dir}" && mkdir -p "${dir}" && cd "${dir}"; }; then
    fail base-canyon "cannot make ${dir}"
    return
  fi
  local ntrip_port tcp_port
  ntrip_port=$(free_port)
  tcp_port=$(free_port)
  {
    echo "station: {id: 1}"
    echo "input: {kind: rinex, source: file, path: ${inst_base}, nav: [${inst_nav}], pace: ${base_pace}}"
    echo "outputs:"
    echo "  dds: {enabled: true, domain: ${domain}, topic: canyon/rtcm, profiles: ${profiles}}"
    echo "  ntrip: {enabled: true, bind: 127.0.0.1, port: ${ntrip_port}, mountpoint: CANYON,"
    echo "          user: rover, password: s3cret}"
    echo "  tcp: {enabled: true, bind: 127.0.0.1, port: ${tcp_port}}"
    echo "log: {progress_interval_s: 0}"
  } > base.yaml
  # The NTRIP rover uploads its position as GGA every second (network RTK); the caster logs the first one.
  rover_yaml rover_ntrip "$(inst_estimator)" \
    "pace: 0, base: ntrip, base_source: 'ntrip://rover:s3cret@127.0.0.1:${ntrip_port}/CANYON', base_wait_s: 5,
    ntrip_gga_interval_s: 1"
  rover_yaml rover_tcp "$(inst_estimator)" \
    "pace: 0, base: tcp, base_source: 'tcp://127.0.0.1:${tcp_port}', base_wait_s: 5"
  timeout 120 "${canyon}" record canyon/rtcm --out base.rtcm3 --domain "${domain}" 2> record_rtcm.log &
  local rec=$!
  timeout 120 "${canyon}" rover --config rover_ntrip.yaml --out ntrip.pos > rover_ntrip.log 2>&1 &
  local r1=$!
  timeout 120 "${canyon}" rover --config rover_tcp.yaml --out tcp.pos > rover_tcp.log 2>&1 &
  local r2=$!
  # A rover with a wrong password: refused (401), reported; it goes on without a base.
  rover_yaml rover_badauth "$(inst_estimator)" "pace: 0, base: ntrip, base_wait_s: 0.5, link_attempts: 2,
    base_source: 'ntrip://rover:wrong@127.0.0.1:${ntrip_port}/CANYON'"
  timeout 120 "${canyon}" rover --config rover_badauth.yaml --out badauth.pos > rover_badauth.log 2>&1 &
  local r3=$!
  # Three clients: the NTRIP rover, the TCP rover, the RTCM recorder (DDS).
  timeout 120 "${canyon}" base --config base.yaml --wait-for-clients 3 > base.log 2>&1
  local base_rc=$?
  wait "${r1}"
  rc[ntrip]=$?
  wait "${r2}"
  rc[tcp]=$?
  wait "${rec}"
  wait "${r3}"
  local badauth_rc=$?
  ((base_rc == 0)) || fail base-canyon "canyon base exit ${base_rc} (${dir}/base.log)"
  if ((badauth_rc == 0)) && grep -q "link lost: gave up reconnecting (last: .*401" rover_badauth.log &&
    ! grep -q wrong rover_badauth.log; then
    pass base-canyon "rover with a wrong NTRIP password: $(grep -m1 'link lost' rover_badauth.log |
      sed 's/^\[[^]]*\] \[[^]]*\] //')"
  else
    fail base-canyon "rover with a wrong NTRIP password: exit ${badauth_rc}, no 401 reported or the password shown" \
      "(${dir}/rover_badauth.log)"
  fi
  local gga
  gga=$(grep -m1 -o 'sends GGA: \$G[A-Z]GGA,[^ ]*' base.log)
  if [[ -n "${gga}" ]]; then
    pass base-canyon "the NTRIP rover uploaded its position, the caster received: ${gga}"
  else
    fail base-canyon "no GGA from the NTRIP rover reached canyon base's caster (${dir}/base.log)"
  fi
  check_two_rovers base-canyon "${dir}"
}

part_base_str2str() {
  local dir="${work}/base-str2str"
  if ! { rm -rf "${dir}" && mkdir -p "${dir}" && cd "${dir}"; }; then
    fail base-str2str "cannot make ${dir}"
    return
  fi
  "${canyon}" convert -q --from rinex "${inst_base}" --nav "${inst_nav}" --out base.rtcm3 > convert.log 2>&1 ||
    { fail base-str2str "canyon convert (${dir}/convert.log)" && return; }
  local tcp_port ntrip_port
  tcp_port=$(free_port)
  ntrip_port=$(free_port)
  mkfifo feed
  # str2str reads the RTCM 3 from the fifo once both rovers are connected (a server drops what comes before).
  timeout 120 str2str -out "tcpsvr://:${tcp_port}" -out "ntripc://:${ntrip_port}/RTKLIB" < feed 2> str2str.log &
  local s2s=$!
  exec 3> feed
  rover_yaml rover_ntrip "$(inst_estimator)" \
    "pace: 0, base: ntrip, base_source: 'ntrip://127.0.0.1:${ntrip_port}/RTKLIB', base_wait_s: 10"
  rover_yaml rover_tcp "$(inst_estimator)" \
    "pace: 0, base: tcp, base_source: 'tcp://127.0.0.1:${tcp_port}', base_wait_s: 10"
  timeout 120 "${canyon}" rover --config rover_ntrip.yaml --out ntrip.pos > rover_ntrip.log 2>&1 &
  local r1=$!
  timeout 120 "${canyon}" rover --config rover_tcp.yaml --out tcp.pos > rover_tcp.log 2>&1 &
  local r2=$!
  wait_clients "${tcp_port}" 1 && wait_clients "${ntrip_port}" 1 ||
    fail base-str2str "the rovers did not connect to str2str"
  sleep 0.5  # the NTRIP rover's request answered
  paced_cat base.rtcm3 200000 >&3  # str2str drops what its clients cannot take at once (see part_ubx)
  wait "${r1}"
  rc[ntrip]=$?
  wait "${r2}"
  rc[tcp]=$?
  exec 3>&-
  kill "${s2s}" 2> /dev/null
  wait "${s2s}" 2> /dev/null
  check_two_rovers base-str2str "${dir}"
}

part_ubx() {
  local dir="${work}/ubx"
  if ! { rm -rf "${dir}" && mkdir -p "${dir}" && cd "${dir}"; }; then
    fail ubx "cannot make ${dir}"
    return
  fi
  local base_pos
  base_pos="$(header_position "${m8p_base}")"
  "${canyon}" convert -q "${m8p_rover_ubx}" --obs-out rover.obs --nav-out rover.nav > convert.log 2>&1 ||
    { fail ubx "canyon convert (${dir}/convert.log)" && return; }
  printf 'mode: rtk\nrtk: {frequencies: 1, systems: [G, R], glonass_ar: off}\n' > process.yaml
  "${canyon}" process -q --config process.yaml --rover rover.obs --base "${m8p_base}" --nav rover.nav \
    --base-pos "${base_pos// /}" --out process.pos > process.log 2>&1
  local est="  mode: rtk
  rtk: {frequencies: 1, systems: [G, R], glonass_ar: off}
  base: ${m8p_base}
  base_position: [${base_pos}]"
  rover_yaml rover_file "${est}
  nav: [rover.nav]" "pace: 0, rover: ubx, rover_source: 'file:${m8p_rover_ubx}', stream_ephemerides: false"
  rover_yaml rover_sfrbx "${est}
  nav: []" "pace: 0, rover: ubx, rover_source: 'file:${m8p_rover_ubx}'"
  local port
  port=$(free_port)
  rover_yaml rover_tcp "${est}
  nav: [rover.nav]" "rover: ubx, rover_source: 'tcp://127.0.0.1:${port}', stream_ephemerides: false,
    link_attempts: 1, link_stall_timeout_s: 2"
  timeout 60 "${canyon}" rover --config rover_file.yaml --out file.pos > rover_file.log 2>&1
  local file_rc=$?
  timeout 60 "${canyon}" rover --config rover_sfrbx.yaml --out sfrbx.pos > rover_sfrbx.log 2>&1
  local sfrbx_rc=$?
  timeout 60 "${canyon}" rover --config rover_sfrbx.yaml --pipeline sequential --out sfrbx_sequential.pos \
    > rover_sfrbx_sequential.log 2>&1
  # Over TCP: str2str serves the log (decompressed) as tcpsvr:// once the rover is connected.
  zcat "${m8p_rover_ubx}" > rover.ubx
  mkfifo feed
  timeout 120 str2str -out "tcpsvr://:${port}" < feed 2> str2str.log &
  local s2s=$!
  exec 3> feed
  timeout 120 "${canyon}" rover --config rover_tcp.yaml --out tcp.pos > rover_tcp.log 2>&1 &
  local rov=$!
  wait_clients "${port}" 1 || fail ubx "the rover did not connect to str2str"
  # At about 100x the receiver's data rate (2 kB/s): str2str drops what its TCP clients cannot take at once (seen:
  # a file pushed in one go lost packets), so the log is fed as a receiver would send it, only faster.
  paced_cat rover.ubx 200000 >&3
  wait "${rov}"
  local tcp_rc=$?
  exec 3>&-
  kill "${s2s}" 2> /dev/null
  wait "${s2s}" 2> /dev/null
  local c
  read -r -a c <<< "$(compare_pos process.pos file.pos)"
  if ((file_rc == 0)) && [[ "${c[3]}" == "${c[4]}" && "${c[2]}" == 0 && "${c[5]}" == 0 ]] &&
    awk -v h="${c[0]}" -v v="${c[1]}" -v m="${kMaxUbxRinexDiffM}" 'BEGIN { exit !(h <= m && v <= m) }'; then
    pass ubx "rover from the UBX file vs canyon process on its RINEX: ${c[4]} solutions, same statuses, max" \
      "difference ${c[0]} m horizontal, ${c[1]} m vertical (RINEX rounding)"
  else
    fail ubx "rover from the UBX file (exit ${file_rc}) vs canyon process on its RINEX: ${c[*]}" \
      "(horizontal, vertical, statuses differing, process records, rover records, unmatched)"
  fi
  # The receiver link ends when str2str has sent the log: exit 1, "link lost", every epoch solved before.
  if same_records tcp.pos file.pos && ((tcp_rc == 1)) && grep -q "link lost" rover_tcp.log; then
    pass ubx "rover from the UBX log over str2str tcpsvr: $(records tcp.pos | wc -l) solutions = the file run" \
      "(byte for byte); then 'link lost', exit 1"
  else
    fail ubx "rover over TCP (exit ${tcp_rc}) differs from the file run (diff ${dir}/tcp.pos ${dir}/file.pos)"
  fi
  # Over a serial line: a pseudo-terminal (a real tty device, no receiver needed) carries the log.
  rm -f pty_name
  python3 - rover.ubx pty_name rover_serial.log << 'PY' &
import os, pty, sys, time
master, slave = pty.openpty()
open(sys.argv[2], "w").write(os.ttyname(slave) + "\n")
os.close(slave)
for _ in range(300):  # write once the rover has opened the device (raw mode): it logs its start line then
    if os.path.exists(sys.argv[3]) and "rover '" in open(sys.argv[3]).read():
        break
    time.sleep(0.1)
time.sleep(0.5)
view = memoryview(open(sys.argv[1], "rb").read())
while view:  # a tty's writes block while the reader is behind: nothing is lost
    view = view[os.write(master, view[:4096]) :]
time.sleep(2)
os.close(master)  # the device goes away
PY
  local feeder=$!
  for _ in $(seq 100); do
    [[ -s pty_name ]] && break
    sleep 0.1
  done
  rover_yaml rover_serial "${est}
  nav: [rover.nav]" "rover: ubx, rover_source: 'serial://$(cat pty_name)?baud=115200', stream_ephemerides: false"
  timeout 120 "${canyon}" rover --config rover_serial.yaml --out serial.pos > rover_serial.log 2>&1
  local serial_rc=$?
  wait "${feeder}"
  if same_records serial.pos file.pos && ((serial_rc == 1)) && grep -q "device gone" rover_serial.log; then
    pass ubx "rover from the UBX log over a serial line (pseudo-terminal $(cat pty_name)): $(records serial.pos |
      wc -l) solutions = the file run (byte for byte); then 'serial link failed: ... device gone', exit 1"
  else
    fail ubx "rover over a serial line (exit ${serial_rc}) differs from the file run (diff ${dir}/serial.pos" \
      "${dir}/file.pos; ${dir}/rover_serial.log)"
  fi
  read -r -a c <<< "$(compare_pos file.pos sfrbx.pos)"
  local first_same
  first_same=$(paste -d'|' <(records file.pos | tail -n "$(records sfrbx.pos | wc -l)") <(records sfrbx.pos) |
    awk -F'|' '$1 != $2 { last = NR } END { print last + 1 }')
  if ((sfrbx_rc == 0)) && same_records sfrbx.pos sfrbx_sequential.pos; then
    pass ubx "rover with the SFRBX ephemerides only (no nav file): ${c[4]} of ${c[3]} epochs solved," \
      "$(records sfrbx.pos | awk '$6 == 1' | wc -l) fixed (nav file: $(records file.pos | awk '$6 == 1' | wc -l));" \
      "identical to the nav-file run from its solution ${first_same} on; threaded = sequential (byte for byte)"
  else
    fail ubx "rover with the SFRBX ephemerides only: exit ${sfrbx_rc} (${dir}/rover_sfrbx.log), or threaded" \
      "differs from sequential (diff ${dir}/sfrbx.pos ${dir}/sfrbx_sequential.pos)"
  fi
}

# expect NAME EXIT_WANTED LOG PATTERN SECONDS_MAX STARTED_AT: checks an exit code, a log line and the time taken
expect() {
  local name=$1 want=$2 got=$3 log=$4 pattern=$5 max_s=$6 start=$7
  local took
  took=$(awk -v s="${start}" -v e="$(date +%s.%N)" 'BEGIN { printf "%.1f", e - s }')
  if ((got == want)) && grep -q -- "${pattern}" "${log}" &&
    awk -v t="${took}" -v m="${max_s}" 'BEGIN { exit !(t <= m) }'; then
    pass bad "${name}: exit ${got} in ${took} s: $(grep -m1 -- "${pattern}" "${log}" | sed 's/^\[[^]]*\] \[[^]]*\] //')"
  else
    fail bad "${name}: exit ${got} (wanted ${want}) in ${took} s (at most ${max_s}), '${pattern}' in ${log}?"
  fi
}

part_bad() {
  local dir="${work}/bad"
  if ! { rm -rf "${dir}" && mkdir -p "${dir}" && cd "${dir}"; }; then
    fail bad "cannot make ${dir}"
    return
  fi
  local base_pos start code port
  base_pos="$(header_position "${m8p_base}")"
  local est="  mode: rtk
  rtk: {frequencies: 1, systems: [G, R], glonass_ar: off}
  base: ${m8p_base}
  base_position: [${base_pos}]
  nav: [${m8p}/rinex/20181004_rover-20181004-1532.nav]"

  # A refused receiver link: two attempts, then exit 1 naming the address.
  port=$(free_port)
  rover_yaml refused "${est}" "rover: ubx, rover_source: 'tcp://127.0.0.1:${port}', link_attempts: 2"
  start=$(date +%s.%N)
  timeout 60 "${canyon}" rover --config refused.yaml --out refused.pos > refused.log 2>&1
  expect "refused receiver link" 1 $? refused.log \
    "tcp://127.0.0.1:${port}: link lost: gave up reconnecting (last: .*refused" 15 "${start}"

  # A refused base link: the rover goes on without a base (single point), exit 0.
  port=$(free_port)
  rover_yaml refused_base "$(inst_estimator)" \
    "pace: 0, base: ntrip, base_source: 'ntrip://127.0.0.1:${port}/NONE', base_wait_s: 0.5, link_attempts: 2"
  start=$(date +%s.%N)
  timeout 60 "${canyon}" rover --config refused_base.yaml --out refused_base.pos > refused_base.log 2>&1
  code=$?
  expect "refused base link" 0 "${code}" refused_base.log "base: ntrip://127.0.0.1:${port}/NONE: link lost" 30 \
    "${start}"
  (($(records refused_base.pos | awk '$6 == 5' | wc -l) == 601)) ||
    fail bad "refused base link: not every one of 601 epochs has its single-point solution"

  # A receiver link that dies mid-log: a server sends the first half of the log and closes.
  zcat "${m8p_rover_ubx}" > rover.ubx
  port=$(free_port)
  python3 - "${port}" rover.ubx << 'PY' &
import socket, sys, time
server = socket.socket()
server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
server.bind(("127.0.0.1", int(sys.argv[1])))
server.listen(1)
server.settimeout(30)
conn, _ = server.accept()
data = open(sys.argv[2], "rb").read()
conn.sendall(data[: len(data) // 2])
time.sleep(0.5)
conn.close()
server.close()
PY
  local peer=$!
  for _ in $(seq 100); do
    [[ -n "$(ss -Htln "( sport = :${port} )" 2> /dev/null)" ]] && break
    sleep 0.1
  done
  rover_yaml dies "${est}" "rover: ubx, rover_source: 'tcp://127.0.0.1:${port}', link_attempts: 2"
  start=$(date +%s.%N)
  timeout 60 "${canyon}" rover --config dies.yaml --out dies.pos > dies.log 2>&1
  code=$?
  wait "${peer}"
  expect "receiver link dies mid-log" 1 "${code}" dies.log "tcp://127.0.0.1:${port}: link lost" 20 "${start}"
  local n
  n=$(records dies.pos | wc -l)
  ((n > 400 && n < 1180)) && pass bad "receiver link dies mid-log: the ${n} epochs received were solved and written" ||
    fail bad "receiver link dies mid-log: ${n} solutions written"

  # A truncated log (cut inside a packet): the epochs before the cut, a warning, exit 0.
  head -c 1234567 rover.ubx > truncated.ubx
  rover_yaml truncated "${est}" "pace: 0, rover: ubx, rover_source: 'file:${dir}/truncated.ubx'"
  start=$(date +%s.%N)
  timeout 60 "${canyon}" rover --config truncated.yaml --out truncated.pos > truncated.log 2>&1
  expect "truncated UBX log ($(records truncated.pos | wc -l) solutions)" 0 $? truncated.log "truncated.ubx: byte" 15 \
    "${start}"

  # Corrupt RTCM frames from the base (bytes flipped in 20 places of canyon convert's stream, served by str2str).
  "${canyon}" convert -q --from rinex "${inst_base}" --nav "${inst_nav}" --out base.rtcm3 > convert.log 2>&1
  python3 - base.rtcm3 corrupt.rtcm3 << 'PY'
import sys
data = bytearray(open(sys.argv[1], "rb").read())
for k in range(1, 21):
    data[k * len(data) // 21] ^= 0xFF
open(sys.argv[2], "wb").write(data)
PY
  port=$(free_port)
  mkfifo feed
  timeout 60 str2str -out "tcpsvr://:${port}" < feed 2> str2str.log &
  local s2s=$!
  exec 3> feed
  rover_yaml corrupt "$(inst_estimator)" "pace: 0, base: tcp, base_source: 'tcp://127.0.0.1:${port}', base_wait_s: 5"
  start=$(date +%s.%N)
  timeout 60 "${canyon}" rover --config corrupt.yaml --out corrupt.pos > corrupt.log 2>&1 &
  local rov=$!
  wait_clients "${port}" 1
  paced_cat corrupt.rtcm3 200000 >&3
  wait "${rov}"
  code=$?
  exec 3>&-
  kill "${s2s}" 2> /dev/null
  wait "${s2s}" 2> /dev/null
  local what
  what="$(grep -c 'base tcp.*: byte' corrupt.log) reported, $(records corrupt.pos | wc -l) solutions"
  expect "corrupt RTCM frames (${what})" 0 "${code}" corrupt.log "base tcp://127.0.0.1:${port}: byte [0-9]*: " 30 \
    "${start}"

  # SIGINT during a real-time replay: stops within a second, the epochs in flight written.
  rover_yaml sigint "${est}" "pace: 1, rover: ubx, rover_source: 'file:${m8p_rover_ubx}'"
  timeout 60 "${canyon}" rover --config sigint.yaml --out sigint.pos > sigint.log 2>&1 &
  rov=$!
  sleep 4
  start=$(date +%s.%N)
  kill -INT "${rov}"
  wait "${rov}"
  expect "SIGINT ($(records sigint.pos | wc -l) solutions)" 0 $? sigint.log "stopped by signal" 3 "${start}"

  # SIGINT while a rover epoch waits (input.base_wait_s 30) for a base that is connected but silent.
  port=$(free_port)
  python3 - "${port}" << 'PY' &
import socket, sys, time
server = socket.socket()
server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
server.bind(("127.0.0.1", int(sys.argv[1])))
server.listen(1)
server.settimeout(30)
conn, _ = server.accept()
time.sleep(15)
PY
  peer=$!
  rover_yaml silent "$(inst_estimator)" \
    "pace: 0, base: tcp, base_source: 'tcp://127.0.0.1:${port}', base_wait_s: 30, link_stall_timeout_s: 60"
  timeout 60 "${canyon}" rover --config silent.yaml --out silent.pos > silent.log 2>&1 &
  rov=$!
  wait_clients "${port}" 1
  sleep 1
  start=$(date +%s.%N)
  kill -INT "${rov}"
  wait "${rov}"
  expect "SIGINT while waiting for a silent base" 0 $? silent.log "stopped by signal" 3 "${start}"
  kill "${peer}" 2> /dev/null
  wait "${peer}" 2> /dev/null
}

mkdir -p "${work}"
for p in ${parts}; do
  case "${p}" in
    base-canyon) part_base_canyon ;;
    base-str2str) part_base_str2str ;;
    ubx) part_ubx ;;
    bad) part_bad ;;
    *) fail "${p}" "unknown part" ;;
  esac
done
exit $((failures > 0 ? 1 : 0))
