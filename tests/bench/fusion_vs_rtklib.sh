#!/usr/bin/env bash
# Issue 5's figures, reproduced in one run: RTKLIB 2.4.3, canyon rtk and canyon fusion side by side.
#  1. Simulated scenarios (canyon simulate, seeds SEEDS): RTKLIB `rnx2rtkp -k config/rtklib/sim.conf`, canyon `process
#     --mode rtk` with config/rtk-urban.yaml (canyon's RTK for street canyons; the ionosphere is estimated on these
#     20 km baselines by `ionosphere: auto`), canyon
#     `process --mode fusion --config config/fusion.yaml`; all scored by `canyon evaluate` against truth.csv: fix rate
#     (fixed / rover epochs), availability, wrong fixes (fixed, 3D error > 0.10 m), 3D RMSE of all solved epochs, and
#     the wall and CPU times of each program on the same files (RTKLIB / fusion = how much faster fusion is).
#  2. Ablations of the fusion on the same files: without VIO covariance propagation (constant 5 cm per axis per epoch),
#     without pruning (no innovation gate, no ILS pruning), without lever-arm calibration, the constant-velocity model
#     instead of VIO; and the gates alone (paper, chi-square), without the false-fix guard, without the C/N0 screen,
#     without the heading error state, without the integrity check, without the heading-free fill-in, without the RTK
#     engine's float consistency test, the C/N0 screen with each elevation bin's own level (not monotone).
#  3. instinct-spirent-rtk-sim (real receiver-simulator GNSS files, 1 Hz, truth with attitude) with VIO from its truth
#     (`canyon simulate --vio-from-truth`), the 5 and then 10 most observed satellites excluded, GPS+Galileo for canyon
#     (RTKLIB 2.4.3 reads no Galileo record of these navigation files: GPS only), and GPS only for all three (also 4
#     excluded: with 5 out of GPS's 8 no program has a position).
# Usage: tests/bench/fusion_vs_rtklib.sh [BUILD_DIR] [SEEDS] [SCENARIOS...]
#   defaults: build, "1 2 3", light-blocked urban-severe
# Environment: KEEP=1 keeps the temp folder (solutions, evaluation.md/json, trajectory.svg, ape.svg per run) and
#   prints its path; ABLATIONS=0 skips part 2; INSTINCT=0 skips part 3; SPEED_RUNS=N times each program N times (5).
# Exit status: 0 done; 1 a run of parts 1 or 2 failed (its cell shows "-", the others go on; listed at the end);
# 2 missing build or tools; 77 (with a SKIP: line) the instinct dataset of part 3 missing and nothing failed. In part 3
# a failing run stays a "-" cell: rows with no solution are expected there (G with 5 or 10 out: canyon process exits 1).
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
seeds=${2:-"1 2 3"}
shift $(($# > 2 ? 2 : $#)) || true
scenarios=("$@")
((${#scenarios[@]} > 0)) || scenarios=(light-blocked urban-severe)
canyon=$build/canyon
conf=$root/config/rtklib/sim.conf
data=${CANYON_SHARED_DATA_DIR:-$root/../shared/data}

[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
command -v rnx2rtkp >/dev/null || { echo "error: rnx2rtkp not installed (run scripts/setup.sh)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "error: python3 needed to read evaluation.json" >&2; exit 2; }

tmp=$(mktemp -d)
if [[ ${KEEP:-0} == 1 ]]; then
  echo "keeping $tmp"
else
  trap 'rm -rf "$tmp"' EXIT
fi

# variant NAME "fusion: overrides" "rtk: overrides": config/fusion.yaml with keys replaced.
variant() {
  local name=$1 fusion_keys=$2 rtk_keys=${3:-} file="$tmp/fusion-$1.yaml"
  cp "$root/config/fusion.yaml" "$file"
  local kv key value
  for kv in $fusion_keys $rtk_keys; do
    key=${kv%%=*}
    value=${kv#*=}
    grep -q "^  $key:" "$file" || { echo "error: no key $key in config/fusion.yaml" >&2; exit 2; }
    sed -i "s|^  $key: [^#]*|  $key: $value |" "$file"
  done
}
variant full ""
variant no-covariance "vio_covariance=false"
variant no-pruning "gate=off" "partial_ar=false"
variant no-calibration "calibrate_lever_arm=false"
variant constant-velocity "prediction=constant_velocity"
variant gate-paper "gate=paper"
variant gate-chi-square "gate=chi_square"
variant no-guard "false_fix_guard=false"
variant no-cn0-screen "cn0_screen=false"
variant no-heading "heading_state=false"
variant no-integrity "integrity_check=false"
variant no-heading-free "heading_free_fill_in=false"
variant no-consistency "" "float_consistency_level=0"
variant cn0-own-bins "cn0_monotone=false"
variant partial-hold "" "partial_hold_sigma_cyc=0.2"

now() { date +%s.%N; }
elapsed() { awk -v s="$1" -v e="$2" 'BEGIN {printf "%.2f", e - s}'; }
# timed FILE COMMAND...: runs the command, writes "wall_s cpu_s" (user + system) to FILE; the command's status is kept.
timed() {
  local file=$1
  shift
  /usr/bin/time -f "%e %U %S" -o "$file.raw" "$@"
  local status=$?
  awk '{printf "%.2f %.2f\n", $1, $2 + $3}' "$file.raw" >"$file"
  return $status
}
# median FILE: "wall_s cpu_s", each the median of its column in FILE (lines of "wall_s cpu_s").
median() {
  local column
  for column in 1 2; do
    cut -d ' ' -f "$column" "$1" | sort -n | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'
  done | paste -d ' ' - -
}
# speed DIR: rnx2rtkp and canyon fusion timed SPEED_RUNS times (default 5) on DIR's files, one after the other in
# turn (the machine's speed drifts from minute to minute: both see the same drift); writes the medians to
# DIR/rtklib.time and DIR/fusion.time.
speed() {
  local dir=$1 i
  : >"$dir/rtklib.times"
  : >"$dir/fusion.times"
  for ((i = 0; i < ${SPEED_RUNS:-5}; ++i)); do
    timed "$dir/run.time" rnx2rtkp -k "$conf" -o "$dir/rtklib-speed.pos" "$dir/rover.obs" "$dir/base.obs" \
      "$dir/nav.rnx" >/dev/null 2>&1 || failed+=("$dir: timed rnx2rtkp")
    cat "$dir/run.time" >>"$dir/rtklib.times"
    timed "$dir/run.time" "$canyon" process -q --config "$tmp/fusion-full.yaml" --rover "$dir/rover.obs" \
      --base "$dir/base.obs" --nav "$dir/nav.rnx" --vio "$dir/vio.csv" --timesync "$dir/timesync.csv" \
      --out "$dir/fusion-speed.pos" 2>/dev/null || failed+=("$dir: timed canyon fusion")
    cat "$dir/run.time" >>"$dir/fusion.times"
  done
  median "$dir/rtklib.times" >"$dir/rtklib.time"
  median "$dir/fusion.times" >"$dir/fusion.time"
}
# "fix% avail% wrong rmse" of label $2 in evaluation.json $1.
figures() {
  [[ -s $1 ]] || { echo "- - - -"; return; }
  python3 - "$1" "$2" <<'EOF'
import json, sys
report = json.load(open(sys.argv[1]))
for s in report["solutions"]:
    if s["label"] == sys.argv[2]:
        rmse = s["ape"]["all"]["3d"]["rmse_m"] if s["ape"]["all"]["3d"] else float("nan")
        print("%.1f %.1f %d %.3f" % (100 * s["status"]["fixed"]["rate"], 100 * s["availability"], s["wrong_fixes"], rmse))
EOF
}
cell() { # fix% avail% wrong rmse -> text
  printf '%5s%% %5s%% w%-3s %8s m' "$1" "$2" "$3" "$4"
}

echo "== 1. Simulated scenarios: RTKLIB : canyon rtk : canyon fusion (fix rate, availability, wrong fixes, 3D RMSE)"
printf '%-14s %4s | %-30s | %-30s | %-30s | %-11s %-11s %6s %6s\n' scenario seed RTKLIB "canyon rtk" "canyon fusion" \
  "RTKLIB s" "fusion s" cpu wall
declare -A sums
failed=()
skip=""
for scenario in "${scenarios[@]}"; do
  for seed in $seeds; do
    dir=$tmp/$scenario-$seed
    "$canyon" simulate -q --scenario "$scenario" --seed "$seed" --out "$dir"
    rnx2rtkp -k "$conf" -o "$dir/rtklib.pos" "$dir/rover.obs" "$dir/base.obs" "$dir/nav.rnx" >/dev/null 2>&1 ||
      failed+=("$scenario seed $seed: rnx2rtkp")
    timed "$dir/rtk.time" "$canyon" process -q --config "$root/config/rtk-urban.yaml" --rover "$dir/rover.obs" \
      --base "$dir/base.obs" --nav "$dir/nav.rnx" --out "$dir/rtk.pos" || failed+=("$scenario seed $seed: canyon rtk")
    "$canyon" process -q --config "$tmp/fusion-full.yaml" --rover "$dir/rover.obs" --base "$dir/base.obs" \
      --nav "$dir/nav.rnx" --vio "$dir/vio.csv" --timesync "$dir/timesync.csv" --out "$dir/fusion.pos" \
      2>"$dir/fusion.log" || failed+=("$scenario seed $seed: canyon fusion ($dir/fusion.log)")
    speed "$dir"
    "$canyon" evaluate -q --truth "$dir/truth.csv" --rover "$dir/rover.obs" --city "$dir/city.geojson" \
      --solution "$dir/rtklib.pos" --label RTKLIB --solution "$dir/rtk.pos" --label "canyon rtk" \
      --solution "$dir/fusion.pos" --label "canyon fusion" --out-dir "$dir/evaluation" ||
      failed+=("$scenario seed $seed: canyon evaluate")
    json=$dir/evaluation/evaluation.json
    read -r a1 a2 a3 a4 <<<"$(figures "$json" RTKLIB)"
    read -r b1 b2 b3 b4 <<<"$(figures "$json" "canyon rtk")"
    read -r c1 c2 c3 c4 <<<"$(figures "$json" "canyon fusion")"
    read -r rtklib_wall rtklib_cpu <"$dir/rtklib.time"
    read -r fusion_wall fusion_cpu <"$dir/fusion.time"
    printf '%-14s %4s | %-30s | %-30s | %-30s | %5s/%-5s %5s/%-5s %5.1fx %5.1fx\n' "$scenario" "$seed" \
      "$(cell "$a1" "$a2" "$a3" "$a4")" "$(cell "$b1" "$b2" "$b3" "$b4")" "$(cell "$c1" "$c2" "$c3" "$c4")" \
      "$rtklib_wall" "$rtklib_cpu" "$fusion_wall" "$fusion_cpu" \
      "$(awk -v a="$rtklib_cpu" -v b="$fusion_cpu" 'BEGIN {print (b > 0 ? a / b : 0)}')" \
      "$(awk -v a="$rtklib_wall" -v b="$fusion_wall" 'BEGIN {print (b > 0 ? a / b : 0)}')"
  done
done
echo "fix = fixed epochs / rover epochs; avail = solved / rover epochs; w = wrong fixes (fixed, 3D error > 0.10 m);"
echo "RMSE = 3D, all solved epochs, against truth.csv; s = wall/CPU seconds (user + system) of rnx2rtkp and of canyon"
echo "process --mode fusion on the same files, medians of ${SPEED_RUNS:-5} runs each taken in turn (fusion includes reading"
echo "the VIO, the time bridge and every alignment); cpu = RTKLIB CPU / fusion CPU, wall = RTKLIB wall / fusion wall (fusion parses the files and"
echo "builds each epoch's geometry on a second thread, ahead of the filter)."

if [[ ${ABLATIONS:-1} != 0 ]]; then
  echo
  echo "== 2. Ablations of canyon fusion (fix rate, availability, wrong fixes, 3D RMSE; same files as above)"
  names=(full no-covariance no-pruning no-calibration constant-velocity gate-paper gate-chi-square no-guard no-cn0-screen
    no-heading no-integrity no-heading-free no-consistency cn0-own-bins partial-hold)
  printf '%-14s %4s' scenario seed
  for name in "${names[@]}"; do printf ' | %-30s' "$name"; done
  echo
  for scenario in "${scenarios[@]}"; do
    for seed in $seeds; do
      dir=$tmp/$scenario-$seed
      printf '%-14s %4s' "$scenario" "$seed"
      for name in "${names[@]}"; do
        out=$dir/ablation-$name
        "$canyon" process -q --config "$tmp/fusion-$name.yaml" --rover "$dir/rover.obs" --base "$dir/base.obs" \
          --nav "$dir/nav.rnx" --vio "$dir/vio.csv" --timesync "$dir/timesync.csv" --out "$out.pos" ||
          failed+=("$scenario seed $seed: ablation $name: canyon process")
        "$canyon" evaluate -q --truth "$dir/truth.csv" --rover "$dir/rover.obs" --solution "$out.pos" \
          --label "$name" --json "$out.json" || { rm -f "$out.json" && failed+=("$scenario seed $seed: ablation $name: evaluate"); }
        read -r f1 f2 f3 f4 <<<"$(figures "$out.json" "$name")"
        printf ' | %-30s' "$(cell "$f1" "$f2" "$f3" "$f4")"
      done
      echo
    done
  done
fi

if [[ ${INSTINCT:-1} != 0 ]]; then
  echo
  inst=$data/instinct-spirent-rtk-sim
  if [[ ! -d $inst ]]; then
    skip="part 3 not run: shared dataset not found at $inst"
    echo "== 3. $skip"
  fi
fi
if [[ ${INSTINCT:-1} != 0 && -z $skip ]]; then
  echo "== 3. instinct-spirent-rtk-sim, dynamic rover, VIO from its truth, most observed satellites excluded"
  obs=$inst/iono-Klob_tropo-Saast
  base_pos="4157177.06580187,671230.476590636,4774767.03105544"
  "$canyon" simulate -q --vio-from-truth "$inst/Rover-dynamic_PVA_Spirent.csv" --out "$tmp/instinct-vio"
  sed 's/^pos1-navsys .*/pos1-navsys        =1/' "$inst/rtklib/rtk_kinematic.conf" >"$tmp/instinct-rtklib.conf"
  printf '%-10s %8s | %-30s | %-30s | %-30s | %7s %7s\n' systems excluded RTKLIB "canyon rtk" "canyon fusion" \
    rtklib_s fusion_s
  for systems in "G, E" "G"; do
    # GPS alone has 8 satellites: with 5 out no one can form a position; 4 out leaves four, three at the end.
    counts="0 5 10"
    [[ $systems == G ]] && counts="0 4 5 10"
    for n in $counts; do
      dir=$tmp/instinct-${systems//[ ,]/}-$n
      mkdir -p "$dir"
      for mode in rtk fusion; do
        cfg=$dir/$mode.yaml
        if [[ $mode == rtk ]]; then cp "$root/config/rtk.yaml" "$cfg"; else cp "$tmp/fusion-full.yaml" "$cfg"; fi
        # The simulation's own models (Klobuchar, Saastamoinen), a short baseline: no ionosphere state.
        sed -i "s|^  systems: .*|  systems: [$systems]|; s|^  ionosphere: [a-z]* |  ionosphere: off |" "$cfg"
        sed -i '/^spp:/,$d' "$cfg"
        printf 'spp:\n  elevation_mask_deg: 15\n  systems: [%s]\n' "$systems" >>"$cfg"
      done
      "$canyon" process -q --config "$dir/rtk.yaml" --rover "$obs/Rover-dynamic_MO_Spirent.obs" \
        --base "$obs/Base-static_MO_Spirent.obs" --base-pos "$base_pos" --nav "$inst/RINEX_GN_Spirent.23N" \
        --nav "$inst/RINEX_EN_Spirent.23L" --exclude-most-observed "$n" --out "$dir/rtk.pos" || true
      excluded=$(sed -n 's/^% excl sats : \([^(]*\).*/\1/p' "$dir/rtk.pos" | tr -s ' ' | sed 's/ $//; s/ /,/g')
      sed "s/^pos1-exclsats .*/pos1-exclsats      =${excluded//,/ }/; s/^ant2-postype .*/ant2-postype       =xyz/; \
s/^ant2-pos1 .*/ant2-pos1          =4157177.06580187/; s/^ant2-pos2 .*/ant2-pos2          =671230.476590636/; \
s/^ant2-pos3 .*/ant2-pos3          =4774767.03105544/" "$tmp/instinct-rtklib.conf" >"$dir/rtklib.conf"
      t0=$(now)
      rnx2rtkp -k "$dir/rtklib.conf" -o "$dir/rtklib.pos" "$obs/Rover-dynamic_MO_Spirent.obs" \
        "$obs/Base-static_MO_Spirent.obs" "$inst/RINEX_GN_Spirent.23N" "$inst/RINEX_EN_Spirent.23L" >/dev/null 2>&1
      t1=$(now)
      "$canyon" process -q --config "$dir/fusion.yaml" --rover "$obs/Rover-dynamic_MO_Spirent.obs" \
        --base "$obs/Base-static_MO_Spirent.obs" --base-pos "$base_pos" --nav "$inst/RINEX_GN_Spirent.23N" \
        --nav "$inst/RINEX_EN_Spirent.23L" --vio "$tmp/instinct-vio/vio.csv" \
        --timesync "$tmp/instinct-vio/timesync.csv" --exclude-most-observed "$n" --out "$dir/fusion.pos" || true
      t2=$(now)
      "$canyon" evaluate -q --truth "$inst/Rover-dynamic_PVA_Spirent.csv" --epochs 601 \
        --solution "$dir/rtklib.pos" --label RTKLIB --solution "$dir/rtk.pos" --label "canyon rtk" \
        --solution "$dir/fusion.pos" --label "canyon fusion" --out-dir "$dir/evaluation" || true
      json=$dir/evaluation/evaluation.json
      read -r a1 a2 a3 a4 <<<"$(figures "$json" RTKLIB)"
      read -r b1 b2 b3 b4 <<<"$(figures "$json" "canyon rtk")"
      read -r c1 c2 c3 c4 <<<"$(figures "$json" "canyon fusion")"
      printf '%-10s %8s | %-30s | %-30s | %-30s | %7s %7s\n' "$systems" "$n" "$(cell "$a1" "$a2" "$a3" "$a4")" \
        "$(cell "$b1" "$b2" "$b3" "$b4")" "$(cell "$c1" "$c2" "$c3" "$c4")" "$(elapsed "$t0" "$t1")" \
        "$(elapsed "$t1" "$t2")"
    done
  done
  echo "excluded: the N satellites of the used constellations tracked in the most rover epochs (canyon's choice,"
  echo "handed to RTKLIB as pos1-exclsats); RTKLIB uses GPS only in both rows (it reads none of these Galileo records)."
fi
if ((${#failed[@]} > 0)); then
  printf 'FAILED: %s\n' "${failed[@]}"
  exit 1
fi
if [[ -n $skip ]]; then
  echo "SKIP: $skip"
  exit 77
fi
