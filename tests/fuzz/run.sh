#!/usr/bin/env bash
# Builds canyon's libFuzzer targets with clang++-14 (-fsanitize=fuzzer,address,undefined; not part of the normal
# gcc build) and runs each for SECONDS: fuzz_rtcm3 (RTCM 3 framing and every message decoder), fuzz_ubx (mixed
# UBX / NMEA / RTCM 3 streams, RAWX, SFRBX navigation words, NAV-PVT, NAV-TIMEGPS), fuzz_ntrip (NTRIP requests and
# responses, chunked coding, source table). A crash, a leak, a sanitizer report or a hang (10 s per input) fails the
# run; the crashing input is left in WORK_DIR. The three run at the same time.
#
# Usage: tests/fuzz/run.sh SECONDS [WORK_DIR]      (default WORK_DIR: <repo>/build/fuzz)
# Exit status: 0 clean, 1 a fuzzer found a problem, the build failed or a seed could not be made, 77 (with a SKIP:
# line) clang++-14 / libFuzzer not installed, or the fuzzers ran clean without the real-data seeds (shared datasets or
# BUILD/canyon missing).
# Seeds: RTCM 3 made by BUILD/canyon from the shared datasets and slices of the u-blox logs.
# Environment: CANYON_BUILD_DIR (default <repo>/build), CANYON_SHARED_DATA_DIR (default <repo>/../shared/data).
set -euo pipefail

if (($# < 1)); then
  echo "usage: $0 SECONDS [WORK_DIR]" >&2
  exit 2
fi
seconds="$1"
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
work="$(realpath -m "${2:-${repo_root}/build/fuzz}")"
data="${CANYON_SHARED_DATA_DIR:-${repo_root}/../shared/data}"
canyon="${CANYON_BUILD_DIR:-${repo_root}/build}/canyon"

cxx="$(command -v clang++-14 || true)"
if [[ -z "${cxx}" ]] || ! compgen -G "/usr/lib/llvm-14/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a" > /dev/null; then
  echo "SKIP: clang++-14 or libclang-rt-14-dev (libFuzzer) not installed (scripts/setup.sh installs them)"
  exit 77
fi

mkdir -p "${work}/obj"
flags=(-std=c++20 -O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer-no-link,address,undefined
  -fno-sanitize-recover=undefined -I"${repo_root}/include" -isystem /usr/include/eigen3)
sources=(src/core/time.cpp src/core/satellite.cpp src/core/ephemeris.cpp src/core/geodesy.cpp
  src/io/bits.cpp src/io/stream_framer.cpp src/io/rtcm3_msm.cpp src/io/rtcm3_station.cpp src/io/rtcm3_ephemeris.cpp
  src/io/rtcm3_legacy.cpp src/io/rtcm3_codec.cpp src/io/nav_message.cpp src/io/ubx.cpp src/io/gnss_stream.cpp
  src/net/ntrip.cpp)

# Objects, rebuilt when their source or any public header is newer; two compilers at a time (2-core machines).
newest_header="$(find "${repo_root}/include" -name '*.hpp' -printf '%T@\n' | sort -n | tail -1)"
objects=()
pids=()
for src in "${sources[@]}"; do
  obj="${work}/obj/$(echo "${src}" | tr '/' '_').o"
  objects+=("${obj}")
  if [[ -f "${obj}" ]] && [[ "${obj}" -nt "${repo_root}/${src}" ]] &&
    [[ "$(stat -c %Y "${obj}")" -ge "${newest_header%.*}" ]]; then
    continue
  fi
  "${cxx}" "${flags[@]}" -c "${repo_root}/${src}" -o "${obj}" &
  pids+=($!)
  if ((${#pids[@]} >= 2)); then
    wait "${pids[0]}" || exit 1
    pids=("${pids[@]:1}")
  fi
done
for pid in "${pids[@]}"; do wait "${pid}" || exit 1; done

targets=(fuzz_rtcm3 fuzz_ubx fuzz_ntrip)
for t in "${targets[@]}"; do
  "${cxx}" "${flags[@]/fuzzer-no-link/fuzzer}" "${repo_root}/tests/fuzz/${t}.cpp" "${objects[@]}" -lz -o "${work}/${t}"
done

# Seed corpora (kept between runs; libFuzzer adds what it finds). A corpus without its seed_* files gets them.
no_seeds=() # what could not be seeded, and why
seed() {
  local dir="$1" file="$2" piece="$3" count="$4"
  [[ -f "${file}" ]] || return 0
  for ((i = 0; i < count; ++i)); do
    dd if="${file}" of="${dir}/seed_$(basename "${file}")_${i}" bs="${piece}" skip="${i}" count=1 status=none
  done
}
mkdir -p "${work}/corpus_rtcm3" "${work}/corpus_ubx" "${work}/corpus_ntrip"
if ! compgen -G "${work}/corpus_rtcm3/seed_*" > /dev/null; then
  if [[ ! -x "${canyon}" ]]; then
    no_seeds+=("RTCM 3: ${canyon} not built")
  elif [[ ! -f "${data}/matrtklib-static/base.obs" ]]; then
    no_seeds+=("RTCM 3: shared dataset not found at ${data}/matrtklib-static")
  else
    if ! "${canyon}" convert "${data}/matrtklib-static/base.obs" --nav "${data}/matrtklib-static/base.nav" \
      --out "${work}/seed.rtcm3" -q > "${work}/seed_rtcm3.log" 2>&1; then
      echo "fuzz: error: the RTCM 3 seed: canyon convert failed (${work}/seed_rtcm3.log)"
      exit 1
    fi
    seed "${work}/corpus_rtcm3" "${work}/seed.rtcm3" 2048 32
  fi
fi
if ! compgen -G "${work}/corpus_ubx/seed_*" > /dev/null; then
  if [[ ! -d "${data}/m8p-galway-20181004" ]]; then
    no_seeds+=("UBX: shared dataset not found at ${data}/m8p-galway-20181004")
  else
    for log in rover-20181004-1532 base-20181004-1452; do
      # The first 256 KiB of the log (head stops reading early: zcat's broken pipe is expected, hence no pipeline).
      head -c 262144 < <(zcat "${data}/m8p-galway-20181004/20181004_${log}.ubx.gz") > "${work}/seed_${log%%-*}.ubx"
      if (($(stat -c %s "${work}/seed_${log%%-*}.ubx") != 262144)); then
        echo "fuzz: error: the UBX seed: cannot read 256 KiB of ${data}/m8p-galway-20181004/20181004_${log}.ubx.gz"
        exit 1
      fi
      seed "${work}/corpus_ubx" "${work}/seed_${log%%-*}.ubx" 4096 32
    done
  fi
fi
if [[ -z "$(ls -A "${work}/corpus_ntrip")" ]]; then
  printf 'GET /CANYON HTTP/1.0\r\nUser-Agent: NTRIP RTKLIB/2.4.3\r\nAuthorization: Basic dXNlcjpwdw==\r\n\r\n' \
    > "${work}/corpus_ntrip/request_v1"
  printf 'GET /CANYON HTTP/1.1\r\nHost: a:2101\r\nNtrip-Version: Ntrip/2.0\r\nUser-Agent: NTRIP x\r\nNtrip-GGA: $GPGGA,1\r\n\r\n' \
    > "${work}/corpus_ntrip/request_v2"
  printf 'HTTP/1.1 200 OK\r\nNtrip-Version: Ntrip/2.0\r\nTransfer-Encoding: chunked\r\n\r\n5\r\nabcde\r\n0\r\n\r\n' \
    > "${work}/corpus_ntrip/response_v2"
  printf 'SOURCETABLE 200 OK\r\nContent-Length: 60\r\n\r\nSTR;A;B;RTCM 3.3;1005;2;GPS;N;XXX;1.0;2.0;0;0;g;none;N;N;0;\r\nENDSOURCETABLE\r\n' \
    > "${work}/corpus_ntrip/sourcetable"
  printf '1a;ext\r\n0123456789abcdef0123456789\r\n0\r\nX: y\r\n\r\n' > "${work}/corpus_ntrip/chunks"
fi

# The fuzzers run side by side (on 2 cores, 3 of them share the cores: fewer executions each, a third of the time).
pids=()
for t in "${targets[@]}"; do
  name="${t#fuzz_}"
  echo "== ${t}: ${seconds} s"
  (cd "${work}" && exec "./${t}" -max_total_time="${seconds}" -timeout=10 -max_len=8192 -rss_limit_mb=2048 \
    -print_final_stats=1 "corpus_${name}" > "${work}/${t}.log" 2>&1) &
  pids+=($!)
done
status=0
summary=()
for i in "${!targets[@]}"; do
  t="${targets[$i]}"
  name="${t#fuzz_}"
  log="${work}/${t}.log"
  if wait "${pids[$i]}"; then
    result="no crash, leak or hang"
  else
    result="FAILED (see ${log} and ${work}/crash-*, leak-*, timeout-*)"
    status=1
    tail -40 "${log}"
  fi
  runs="$(grep -o 'stat::number_of_executed_units: *[0-9]*' "${log}" | grep -o '[0-9]*$' || echo '?')"
  cov="$(grep -o 'cov: [0-9]*' "${log}" | tail -1 | grep -o '[0-9]*' || echo '?')"
  corpus="$(ls "${work}/corpus_${name}" | wc -l)"
  summary+=("$(printf '%-11s %6s s  %12s executions  coverage %6s  corpus %6s  %s' "${t}" "${seconds}" "${runs}" \
    "${cov}" "${corpus}" "${result}")")
done
echo
printf '%s\n' "${summary[@]}"
if ((status == 0 && ${#no_seeds[@]} > 0)); then
  echo "SKIP: fuzzed without the real-data seeds: $(printf '%s; ' "${no_seeds[@]}")"
  exit 77
fi
exit "${status}"
