#!/usr/bin/env bash
# canyon RTK against RTKLIB rnx2rtkp, side by side, on the shared datasets: per dataset and AR mode, RTKLIB runs
# with the dataset's shipped option file (../shared/data/*/rtklib/*.conf, same input files as that folder's run.sh)
# and canyon with an equivalent YAML configuration written next to a copy of that option file in a temp folder;
# both are timed (whole-process wall time, median of RUNS) and both .pos files are scored by bench_eval_pos
# (canyon::eval): fix rate, 3D RMSE against the truth where one exists, wrong fixes (fixed, 3D error > 0.10 m),
# and the largest distance between the two solutions on epochs both fixed.
#
# canyon is run as
#   canyon process --mode rtk --config FILE.yaml --rover OBS --base OBS --nav NAV... --base-pos X,Y,Z --out SOL.pos
# with FILE.yaml:
#   mode: rtk
#   rtk:
#     ar_mode: continuous | instantaneous | fix_and_hold     <- pos2-armode
#     elevation_mask_deg: 15                                  <- pos1-elmask
#     frequencies: 2                                          <- pos1-frequency (l1 = 1, l1+2 = 2, l1+2+3 = 3)
#     systems: [G, E]                                         <- pos1-navsys (1 G, 4 R, 8 E, 16 J, 32 C)
#     ratio_threshold: 3.0                                    <- pos2-arthres
#     glonass_ar: off | on                                    <- pos2-gloarmode
#     troposphere: saastamoinen | off                         <- pos1-tropopt (with spp models off likewise)
# (keys as in config/rtk.yaml; the other options keep their defaults there). A failing canyon or rnx2rtkp run is a
# row marked "fail" (the others still run) and makes the exit status 1.
#
# Usage: tests/bench/rtk_vs_rtklib.sh [BUILD_DIR] [RUNS]     (defaults: build, 5 timed runs of each program)
# Environment: CANYON_SHARED_DATA_DIR (default ../shared/data), KEEP=1 keeps the temp folder and prints its path,
# ONLY=REGEX runs only the rows whose dataset name matches (e.g. ONLY=cssrlib-kinematic for the speed target).
# Exit status: 0 done, 1 a canyon or rnx2rtkp run failed, 2 missing build or tools, 77 (with a SKIP: line) a dataset
# (or the whole shared data folder) missing and nothing failed.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
runs=${2:-5}
data=${CANYON_SHARED_DATA_DIR:-$root/../shared/data}
canyon=$build/canyon
eval_pos=$build/tests/bench/bench_eval_pos

[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
[[ -x $eval_pos ]] || { echo "error: $eval_pos not built (CANYON_BUILD_BENCHMARKS=ON)" >&2; exit 2; }
command -v rnx2rtkp >/dev/null || { echo "error: rnx2rtkp not installed (run scripts/setup.sh)" >&2; exit 2; }
[[ -d $data ]] || { echo "SKIP: shared datasets not found at $data"; exit 77; }
data=$(cd "$data" && pwd)

tmp=$(mktemp -d)
if [[ ${KEEP:-0} == 1 ]]; then
  echo "keeping $tmp"
else
  trap 'rm -rf "$tmp"' EXIT
fi

# Truths (dataset READMEs).
cssrlib_static_truth="ecef:-3962108.673,3381309.574,3668678.638"
matrtklib_truth="llh:35.13469901,136.97757549,104.8626"
instinct_dynamic_truth="$data/instinct-spirent-rtk-sim/Rover-dynamic_PVA_Spirent.csv"
instinct_static_truth="ecef:4156857.1195929,673209.028774142,4774767.03105544"

# name | conf (in the dataset's rtklib/) | rover | base | truth spec or - | nav files (|-separated), paths in the dataset
instinct_nav="RINEX_GN_Spirent.23N|RINEX_EN_Spirent.23L"
runs_table=(
  "cssrlib-static-doy078|rtk_kinematic.conf|SEPT078M1.21O|3034078M1.21O|$cssrlib_static_truth|SEPT078M.21P"
  "cssrlib-static-doy078|rtk_kinematic_inst.conf|SEPT078M1.21O|3034078M1.21O|$cssrlib_static_truth|SEPT078M.21P"
  "cssrlib-static-doy078+J|rtk_kinematic_withqzss.conf|SEPT078M1.21O|3034078M1.21O|$cssrlib_static_truth|SEPT078M.21P"
  "matrtklib-static|rtk_kinematic.conf|rover.obs|base.obs|$matrtklib_truth|base.nav"
  "matrtklib-static|rtk_kinematic_inst.conf|rover.obs|base.obs|$matrtklib_truth|base.nav"
  "matrtklib-static|rtk_kinematic_fixhold.conf|rover.obs|base.obs|$matrtklib_truth|base.nav"
)
for variant in iono-Klob_tropo-Saast iono-none_tropo-none; do
  suffix=""
  short=klob
  if [[ $variant == iono-none_tropo-none ]]; then suffix=_noatm; short=noatm; fi
  for mode in kinematic kinematic_inst kinematic_fixhold; do
    runs_table+=(
      "instinct-$short-dynamic|rtk_${mode}${suffix}.conf|$variant/Rover-dynamic_MO_Spirent.obs|$variant/Base-static_MO_Spirent.obs|$instinct_dynamic_truth|$instinct_nav"
      "instinct-$short-static2km|rtk_${mode}${suffix}.conf|$variant/Rover-static-2km-east_MO_Spirent.obs|$variant/Base-static_MO_Spirent.obs|$instinct_static_truth|$instinct_nav"
    )
  done
done
runs_table+=(
  "cssrlib-kinematic-doy265|rtk_kinematic.conf|SEPT265G.21O|3034265G.21O|-|SEPT2650.21P"
  "cssrlib-kinematic-doy265|rtk_kinematic_inst.conf|SEPT265G.21O|3034265G.21O|-|SEPT2650.21P"
  "cssrlib-kinematic-doy265+J|rtk_kinematic_withqzss.conf|SEPT265G.21O|3034265G.21O|-|SEPT2650.21P"
  "cssrlib-kinematic-doy265+J|rtk_kinematic_inst_withqzss.conf|SEPT265G.21O|3034265G.21O|-|SEPT2650.21P"
  "m8p-galway-20181004|rtk_kinematic_L1_hdr.conf|rinex/20181004_rover-20181004-1532.obs|rinex/20181004_base-20181004-1452.obs|-|rinex/20181004_base-20181004-1452.nav"
)

# Folder of a dataset from the table name (the +J and instinct variants share one).
dataset_dir() {
  case $1 in
    instinct-*) echo instinct-spirent-rtk-sim ;;
    *) echo "${1%+J}" ;;
  esac
}

# conf_value, llh_to_ecef, base_position, write_yaml: RTKLIB option files read as canyon configurations.
# shellcheck source=tests/bench/rtklib_conf.sh
source "$root/tests/bench/rtklib_conf.sh"

# Milliseconds one run takes: bash's `time` over the command, median of $runs.
median() { sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
run_ms() {
  local TIMEFORMAT=%R seconds
  seconds=$({ time "$@" >/dev/null 2>&1; } 2>&1)
  awk -v s="$seconds" 'BEGIN {printf "%.1f\n", s * 1000}'
}
time_ms() {
  local i
  for ((i = 0; i < runs; i++)); do run_ms "$@"; done | median
}
# Two commands timed in turn (A, B, A, B, ...: both see the same machine): "median_A median_B".
time_pair_ms() {
  local a=() i times_a="" times_b=""
  while [[ $1 != -- ]]; do a+=("$1"); shift; done
  shift
  for ((i = 0; i < runs; i++)); do
    times_a+="$(run_ms "${a[@]}")"$'\n'
    times_b+="$(run_ms "$@")"$'\n'
  done
  echo "$(printf '%s' "$times_a" | median) $(printf '%s' "$times_b" | median)"
}

# Value of key $2 in a bench_eval_pos --kv line $1, "-" if absent.
kv() { tr ' ' '\n' <<<"$1" | awk -F= -v k="$2" '$1 == k {print $2; found = 1} END {if (!found) print "-"}'; }

failures=()
missing=()
row() { printf '%-27s %-13s %8s %8s %9s %9s %6s %10s %10s %10s %7s\n' "$@"; }
row dataset "AR mode" "c fix%" "R fix%" "c RMSE m" "R RMSE m" "c wrng" "max dfix m" "canyon ms" "RTKLIB ms" speedup
for entry in "${runs_table[@]}"; do
  IFS='|' read -r name conf_name rover base truth navs <<<"$entry"
  [[ -z ${ONLY:-} || $name =~ $ONLY ]] || continue
  IFS='|' read -r -a nav_files <<<"$navs"
  dir=$data/$(dataset_dir "$name")
  conf=$dir/rtklib/$conf_name
  if [[ ! -f $conf || ! -f $dir/$rover || ! -f $dir/$base ]]; then
    echo "$name $conf_name: files missing, not run"
    missing+=("$name $conf_name")
    continue
  fi
  work=$tmp/$name-${conf_name%.conf}
  mkdir -p "$work"
  cp "$conf" "$work/rtklib.conf"
  write_yaml "$conf" >"$work/canyon.yaml"
  armode=$(awk '/ar_mode:/ {print $2}' "$work/canyon.yaml")
  navs_abs=()
  for n in "${nav_files[@]}"; do navs_abs+=("$dir/$n"); done
  epochs_in=$(grep -c '^> ' "$dir/$rover" || true)
  truth_args=()
  [[ $truth == - ]] || truth_args=(--truth "$truth")

  rtklib_cmd=(rnx2rtkp -k "$work/rtklib.conf" -o "$work/rtklib.pos" "$dir/$rover" "$dir/$base" "${navs_abs[@]}")
  if ! "${rtklib_cmd[@]}" >"$work/rtklib.log" 2>&1; then
    echo "$name $conf_name: rnx2rtkp failed, see $work/rtklib.log" >&2
    failures+=("$name $conf_name: rnx2rtkp")
    row "$name" "$armode" fail fail
    continue
  fi
  rtklib_ms=-
  rtklib_kv=$("$eval_pos" "$work/rtklib.pos" "${truth_args[@]}" --epochs-in "$epochs_in" --kv)

  canyon_fix="-" canyon_rmse="-" canyon_wrong="-" max_dfix="-" canyon_ms="-" speedup="-"
  base_pos=$(base_position "$conf" "$dir/$base")
  canyon_cmd=("$canyon" process -q --mode rtk --config "$work/canyon.yaml" --rover "$dir/$rover" --base "$dir/$base")
  for n in "${navs_abs[@]}"; do canyon_cmd+=(--nav "$n"); done
  canyon_cmd+=(--base-pos "$base_pos" --out "$work/canyon.pos")
  set +e
  "${canyon_cmd[@]}" >"$work/canyon.log" 2>&1
  rc=$?
  set -e
  if ((rc != 0)); then
    canyon_fix="fail"
    echo "$name $conf_name: canyon failed (exit $rc), see $work/canyon.log" >&2
    failures+=("$name $conf_name: canyon exit $rc")
  else
    read -r rtklib_ms canyon_ms < <(time_pair_ms "${rtklib_cmd[@]}" -- "${canyon_cmd[@]}")
    canyon_kv=$("$eval_pos" "$work/canyon.pos" "${truth_args[@]}" --epochs-in "$epochs_in" --ref "$work/rtklib.pos" --kv)
    canyon_fix=$(kv "$canyon_kv" fixed_pct)
    canyon_rmse=$(kv "$canyon_kv" rmse_3d_m)
    canyon_wrong=$(kv "$canyon_kv" wrong_fixes)
    max_dfix=$(kv "$canyon_kv" max_fixed_dist_m)
    speedup=$(awk -v c="$canyon_ms" -v r="$rtklib_ms" 'BEGIN {if (c > 0) printf "%.1fx", r / c; else print "-"}')
  fi
  [[ $rtklib_ms != - ]] || rtklib_ms=$(time_ms "${rtklib_cmd[@]}")
  row "$name" "$armode" "$canyon_fix" "$(kv "$rtklib_kv" fixed_pct)" "$canyon_rmse" \
    "$(kv "$rtklib_kv" rmse_3d_m)" "$canyon_wrong" "$max_dfix" "$canyon_ms" "$rtklib_ms" "$speedup"
done
echo "fix% = fixed epochs / rover epochs; RMSE = 3D RMSE of all solutions vs truth (- : no truth); c wrng = canyon's"
echo "fixed epochs more than 0.10 m from the truth; max dfix = largest canyon-RTKLIB distance on epochs both fixed;"
echo "times = whole-process wall time, median of $runs runs, canyon and RTKLIB in turn."
if ((${#failures[@]} > 0)); then
  printf 'FAILED: %s\n' "${failures[@]}"
  exit 1
fi
if ((${#missing[@]} > 0)); then
  echo "SKIP: rows not run, their files missing in $data: $(printf '%s; ' "${missing[@]}")"
  exit 77
fi
exit 0
