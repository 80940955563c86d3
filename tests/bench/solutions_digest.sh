#!/usr/bin/env bash
# Every solution the benches produce, on fixed inputs, with one SHA-256 per output file: run it on two builds and
# diff the two digests to show that a change (a refactoring) keeps the solutions byte for byte, or which differ.
#   rtk        tests/bench/rtk_vs_rtklib.sh (one timed run): canyon rtk on every shared dataset and AR mode
#   fusion     tests/bench/fusion_vs_rtklib.sh (seeds SEEDS of light-blocked, urban-moderate, urban-severe; one
#              timed run): canyon rtk (config/rtk-urban.yaml) and fusion (config/fusion.yaml), every ablation, and
#              instinct with VIO from its truth and satellites excluded
#   layouts    canyon process --pipeline sequential | bridge-ahead | threaded on urban-severe seed 1 (fusion) and on
#              instinct (rtk), and instinct with the constant-acceleration model (rtk dynamics)
#   spp        canyon process --mode spp on the shared datasets of tests/bench/spp_vs_rtklib.sh
#   demo       canyon demo (its solutions, evaluation and plots)
#   loopback   tests/bench/rover_loopback.sh both: the DDS rover's recorded .pos (equal to canyon process, checked
#              by the script itself)
#   convert    canyon convert: RINEX -> RTCM 3 (MSM7 and MSM4) -> RINEX, and a u-blox log -> RINEX
# Temporary folder names inside the outputs (the .pos headers name their inputs) are replaced by a fixed token.
# Usage: tests/bench/solutions_digest.sh BUILD_DIR OUT_DIR [PARTS]   (default parts: all of the above)
#   env SEEDS (default "1 2 3"), CANYON_SHARED_DATA_DIR.
# Prints "sha256  part/file" lines, sorted, also written to OUT_DIR/digest.txt; the outputs stay in OUT_DIR.
# Exit status: 0 done, 1 a part failed to run, 2 missing build or tools.
set -uo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: solutions_digest.sh BUILD_DIR OUT_DIR [PARTS]}" && pwd)
out=$(realpath -m "${2:?usage: solutions_digest.sh BUILD_DIR OUT_DIR [PARTS]}")
parts=${3:-rtk fusion layouts spp demo loopback convert}
seeds=${SEEDS:-1 2 3}
data=$(realpath -m "${CANYON_SHARED_DATA_DIR:-$root/../shared/data}")
canyon=$build/canyon
[[ -x $canyon ]] || { echo "error: $canyon not built" >&2; exit 2; }
command -v rnx2rtkp > /dev/null || { echo "error: rnx2rtkp not installed (scripts/setup.sh)" >&2; exit 2; }
[[ -d $data ]] || { echo "error: no shared data at $data" >&2; exit 2; }
mkdir -p "$out"
failed=0

# normalise TMP_DIR: stdin to stdout with what differs from run to run replaced: the temporary folder ("TMP"), the
# shared data folder however reached ("DATA"), the run date of a RINEX header ("DATE").
normalise() {
  sed -e "s|$1|TMP|g" -e "s|$root/../shared/data|DATA|g" -e "s|$data|DATA|g" \
    -e '/PGM \/ RUN BY \/ DATE/s/[0-9]\{8\} [0-9]\{6\} UTC/DATE/'
}

# keep PART TMP_DIR PATTERN...: copies the files matching the patterns under TMP_DIR to OUT/PART, normalised.
keep() {
  local part=$1 tmp=$2
  shift 2
  local pattern file rel
  for pattern in "$@"; do
    while IFS= read -r file; do
      rel=${file#"$tmp"/}
      mkdir -p "$out/$part/$(dirname "$rel")"
      normalise "$tmp" < "$file" > "$out/$part/$rel"
    done < <(find "$tmp" -type f -name "$pattern" | sort)
  done
}

# kept_tmp LOG: the folder a bench script printed as "keeping DIR".
kept_tmp() { sed -n 's/^keeping //p' "$1" | head -1; }

part_rtk() {
  KEEP=1 bash "$root/tests/bench/rtk_vs_rtklib.sh" "$build" 1 > "$out/rtk.log" 2>&1 || return 1
  local tmp
  tmp=$(kept_tmp "$out/rtk.log")
  keep rtk "$tmp" canyon.pos
  rm -rf "$tmp"
}

part_fusion() {
  KEEP=1 SPEED_RUNS=1 bash "$root/tests/bench/fusion_vs_rtklib.sh" "$build" "$seeds" light-blocked urban-moderate \
    urban-severe > "$out/fusion.log" 2>&1 || return 1
  local tmp
  tmp=$(kept_tmp "$out/fusion.log")
  keep fusion "$tmp" rtk.pos fusion.pos 'ablation-*.pos'
  rm -rf "$tmp"
}

part_layouts() {
  local tmp=$out/layouts.work
  rm -rf "$tmp" && mkdir -p "$tmp"
  "$canyon" simulate -q --scenario urban-severe --seed 1 --out "$tmp/sim" || return 1
  local layout inst=$data/instinct-spirent-rtk-sim obs
  obs=$inst/iono-Klob_tropo-Saast
  for layout in sequential bridge-ahead threaded; do
    "$canyon" process -q --config "$root/config/fusion.yaml" --rover "$tmp/sim/rover.obs" --base "$tmp/sim/base.obs" \
      --nav "$tmp/sim/nav.rnx" --vio "$tmp/sim/vio.csv" --timesync "$tmp/sim/timesync.csv" --pipeline "$layout" \
      --out "$tmp/fusion-$layout.pos" || return 1
    "$canyon" process -q --config "$root/config/rtk.yaml" --rover "$obs/Rover-dynamic_MO_Spirent.obs" \
      --base "$obs/Base-static_MO_Spirent.obs" --nav "$inst/RINEX_GN_Spirent.23N" --nav "$inst/RINEX_EN_Spirent.23L" \
      --pipeline "$layout" --out "$tmp/rtk-$layout.pos" --nmea "$tmp/rtk-$layout.nmea" || return 1
  done
  # The constant-acceleration model (rtk dynamics), which no shipped configuration uses.
  sed 's/^  dynamics: .*/  dynamics: true/' "$root/config/rtk.yaml" > "$tmp/rtk-dynamics.yaml"
  "$canyon" process -q --config "$tmp/rtk-dynamics.yaml" --rover "$obs/Rover-dynamic_MO_Spirent.obs" \
    --base "$obs/Base-static_MO_Spirent.obs" --nav "$inst/RINEX_GN_Spirent.23N" --nav "$inst/RINEX_EN_Spirent.23L" \
    --out "$tmp/rtk-dynamics.pos" || return 1
  keep layouts "$tmp" '*.pos' '*.nmea'
  rm -rf "$tmp"
}

part_spp() {
  local tmp=$out/spp.work line name systems rover navs nav_args
  rm -rf "$tmp" && mkdir -p "$tmp"
  for line in "rtklib-test-gsi-2005|G|rtklib-test-gsi-2005/07590920.05o|rtklib-test-gsi-2005/07590920.05n" \
    "cssrlib-static-doy078|G,E,J|cssrlib-static-doy078/SEPT078M1.21O|cssrlib-static-doy078/SEPT078M.21P" \
    "cssrlib-kinematic-doy265|G,E,J|cssrlib-kinematic-doy265/SEPT265G.21O|cssrlib-kinematic-doy265/SEPT2650.21P" \
    "m8p-galway-20181004|G,R,E|m8p-galway-20181004/rinex/20181004_rover-20181004-1532.obs|m8p-galway-20181004/rinex/20181004_base-20181004-1452.nav" \
    "matrtklib-static|G|matrtklib-static/rover.obs|matrtklib-static/base.nav"; do
    IFS='|' read -r name systems rover navs <<< "$line"
    printf 'mode: spp\nspp:\n  systems: [%s]\n' "$systems" > "$tmp/$name.yaml"
    nav_args=()
    for n in ${navs//|/ }; do nav_args+=(--nav "$data/$n"); done
    "$canyon" process -q --config "$tmp/$name.yaml" --rover "$data/$rover" "${nav_args[@]}" \
      --out "$tmp/$name.pos" || return 1
  done
  keep spp "$tmp" '*.pos'
  rm -rf "$tmp"
}

part_demo() {
  local tmp=$out/demo.work
  rm -rf "$tmp"
  (cd "$root" && "$canyon" demo --out "$tmp" > "$out/demo.log" 2>&1) || return 1
  keep demo "$tmp" '*.pos' '*.md' '*.svg'
  rm -rf "$tmp"
}

part_loopback() {
  local tmp=$out/loopback.work
  rm -rf "$tmp"
  bash "$root/tests/bench/rover_loopback.sh" both "$build" "$tmp" > "$out/loopback.log" 2>&1 || return 1
  # The recorded .pos names the programs in its header: records only.
  while IFS= read -r file; do
    mkdir -p "$out/loopback/$(dirname "${file#"$tmp"/}")"
    grep -v '^%' "$file" > "$out/loopback/${file#"$tmp"/}"
  done < <(find "$tmp" -type f -name '*.pos' | sort)
  rm -rf "$tmp"
}

part_convert() {
  local tmp=$out/convert.work inst=$data/instinct-spirent-rtk-sim msm
  local obs=$inst/iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs
  rm -rf "$tmp" && mkdir -p "$tmp"
  for msm in 7 4; do
    "$canyon" convert "$obs" --nav "$inst/RINEX_GN_Spirent.23N" --msm "$msm" --station-id 7 \
      --out "$tmp/base-msm$msm.rtcm3" > /dev/null 2>&1 || return 1
    "$canyon" convert "$tmp/base-msm$msm.rtcm3" --time "2023-01-08 10:00:00" --obs-out "$tmp/base-msm$msm.obs" \
      --nav-out "$tmp/base-msm$msm.nav" > /dev/null 2>&1 || return 1
  done
  local ubx
  ubx=$(find "$data/m8p-galway-20181004" -name '*.ubx*' | sort | head -1)
  if [[ -n $ubx ]]; then
    "$canyon" convert "$ubx" --obs-out "$tmp/m8p.obs" --nav-out "$tmp/m8p.nav" > /dev/null 2>&1 || return 1
  fi
  keep convert "$tmp" '*.rtcm3' '*.obs' '*.nav'
  rm -rf "$tmp"
}

for part in $parts; do
  start=$(date +%s)
  if ! "part_$part"; then
    echo "solutions_digest: part $part failed (see $out/$part.log if any)" >&2
    failed=1
  fi
  echo "solutions_digest: $part done in $(($(date +%s) - start)) s" >&2
done
(cd "$out" && find $parts -type f 2> /dev/null | sort | xargs -r sha256sum) > "$out/digest.txt"
cat "$out/digest.txt"
exit "$failed"
