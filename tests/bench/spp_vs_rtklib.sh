#!/usr/bin/env bash
# Times canyon's SPP (`canyon process --mode spp`) and RTKLIB's (`rnx2rtkp` in single-point mode) side by side on
# the same files with the same models (elevation mask 15 deg, broadcast Klobuchar ionosphere, Saastamoinen
# troposphere, same constellations; rnx2rtkp's built-in defaults would apply no atmosphere model at all), in one
# run, and prints the ratio per dataset.
# Whole-process wall time (start-up, reading RINEX and navigation, solving, writing .pos), median of N runs,
# batches interleaved so that both see the same machine load.
#
# Usage: tests/bench/spp_vs_rtklib.sh [BUILD_DIR] [RUNS]      (defaults: build, 11 batches of BATCH=5 runs)
# Exit status: 0 if canyon is at least MIN_SPEEDUP (default 5) times faster on every dataset, else 1 (also when a
# canyon or rnx2rtkp run fails: each is run once, checked, before the timed runs); 2 missing build or tools; 77 (with
# a SKIP: line) a dataset (or the whole shared data folder) missing and nothing failed.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
runs=${2:-11}
min_speedup=${MIN_SPEEDUP:-5}
data=${CANYON_SHARED_DATA_DIR:-$root/../shared/data}
canyon=$build/canyon

[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
command -v rnx2rtkp >/dev/null || { echo "error: rnx2rtkp not installed (run scripts/setup.sh)" >&2; exit 2; }
[[ -d $data ]] || { echo "SKIP: shared datasets not found at $data"; exit 77; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# name | systems | rover | nav files...
datasets=(
  "rtklib-test-gsi-2005|G|rtklib-test-gsi-2005/07590920.05o|rtklib-test-gsi-2005/07590920.05n"
  "cssrlib-static-doy078|G,E,J|cssrlib-static-doy078/SEPT078M1.21O|cssrlib-static-doy078/SEPT078M.21P"
  "cssrlib-kinematic-doy265|G,E,J|cssrlib-kinematic-doy265/SEPT265G.21O|cssrlib-kinematic-doy265/SEPT2650.21P"
  "matrtklib-static|G,R,E,C,J|matrtklib-static/rover.obs|matrtklib-static/base.nav"
  "m8p-galway-20181004|G,R,J|m8p-galway-20181004/rinex/20181004_rover-20181004-1532.obs|m8p-galway-20181004/rinex/20181004_rover-20181004-1532.nav"
  "instinct-spirent-rtk-sim|G,E|instinct-spirent-rtk-sim/iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs|instinct-spirent-rtk-sim/RINEX_GN_Spirent.23N|instinct-spirent-rtk-sim/RINEX_EN_Spirent.23L"
)

# Microseconds one run of a command takes: bash's own `time` over a batch of runs (no timing processes of its own
# in the measurement), divided by the batch size.
batch=${BATCH:-5}
elapsed() {
  local TIMEFORMAT=%R seconds
  seconds=$({ time for ((k = 0; k < batch; k++)); do "$@" >/dev/null 2>&1; done; } 2>&1)
  awk -v s="$seconds" -v b="$batch" 'BEGIN {printf "%d\n", s * 1e6 / b}'
}

median() { sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

printf '%-26s %7s %12s %12s %9s\n' dataset epochs "canyon ms" "RTKLIB ms" speedup
status=0
missing=()
for entry in "${datasets[@]}"; do
  IFS='|' read -r name systems rover navs <<<"$entry"
  IFS='|' read -r -a nav_files <<<"$navs"
  if [[ ! -f $data/$rover ]]; then
    echo "$name: $data/$rover missing, not run"
    missing+=("$name")
    continue
  fi
  letters=${systems//,/, }
  cat >"$tmp/$name.yaml" <<YAML
mode: spp
spp:
  systems: [$letters]
  elevation_mask_deg: 15
YAML
  canyon_args=(process -q --config "$tmp/$name.yaml" --rover "$data/$rover" --out "$tmp/canyon.pos")
  mask=0
  [[ $systems == *G* ]] && mask=$((mask | 1))
  [[ $systems == *R* ]] && mask=$((mask | 4))
  [[ $systems == *E* ]] && mask=$((mask | 8))
  [[ $systems == *J* ]] && mask=$((mask | 16))
  [[ $systems == *C* ]] && mask=$((mask | 32))
  printf 'pos1-posmode=single\npos1-elmask=15\npos1-ionoopt=brdc\npos1-tropopt=saas\npos1-sateph=brdc\npos1-navsys=%d\n' \
    "$mask" >"$tmp/$name.conf"
  rtklib_args=(-k "$tmp/$name.conf" -o "$tmp/rtklib.pos" "$data/$rover")
  for n in "${nav_files[@]}"; do
    canyon_args+=(--nav "$data/$n")
    rtklib_args+=("$data/$n")
  done
  # One checked run of each first: the timed runs discard the exit status (a failing program would time as fast).
  if ! "$canyon" "${canyon_args[@]}" >"$tmp/canyon.log" 2>&1; then
    echo "$name: canyon failed: $(tail -n 1 "$tmp/canyon.log")"
    status=1
    continue
  fi
  if ! rnx2rtkp "${rtklib_args[@]}" >"$tmp/rtklib.log" 2>&1; then
    echo "$name: rnx2rtkp failed: $(tail -n 1 "$tmp/rtklib.log")"
    status=1
    continue
  fi
  : >"$tmp/c" ; : >"$tmp/r"
  for ((i = 0; i < runs; i++)); do
    elapsed "$canyon" "${canyon_args[@]}" >>"$tmp/c"
    elapsed rnx2rtkp "${rtklib_args[@]}" >>"$tmp/r"
  done
  c=$(median <"$tmp/c")
  r=$(median <"$tmp/r")
  epochs=$(grep -vc '^%' "$tmp/canyon.pos" || true)
  speedup=$(awk -v c="$c" -v r="$r" 'BEGIN {printf "%.1f", r / c}')
  printf '%-26s %7d %12.1f %12.1f %8sx\n' "$name" "$epochs" "$(awk -v c="$c" 'BEGIN{print c/1000}')" \
    "$(awk -v r="$r" 'BEGIN{print r/1000}')" "$speedup"
  awk -v s="$speedup" -v m="$min_speedup" 'BEGIN {exit !(s >= m)}' || status=1
done
[[ $status -eq 0 ]] && echo "canyon SPP is at least ${min_speedup}x faster than RTKLIB rnx2rtkp single-point on every dataset" ||
  echo "canyon SPP is NOT ${min_speedup}x faster than RTKLIB rnx2rtkp single-point on every dataset"
if ((status == 0 && ${#missing[@]} > 0)); then
  echo "SKIP: datasets not run, their files missing in $data: ${missing[*]}"
  exit 77
fi
exit $status
