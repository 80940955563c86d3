#!/usr/bin/env bash
# canyon RTK and RTKLIB side by side on generated scenarios (canyon simulate). For each scenario and seed: generate
# into a temp folder, run
#   RTKLIB  rnx2rtkp -k config/rtklib/sim.conf (kinematic, forward, continuous AR, ratio 3, L1+L2, 15 deg mask,
#           base position from the base header, ionosphere est-stec) and the same with pos1-ionoopt=brdc;
#   canyon  canyon process --mode rtk --config config/rtk-urban.yaml (SNR weighting; ionosphere: auto, estimated
#           on baselines beyond 10 km, so here) and with config/rtk.yaml (the defaults: elevation weighting);
# and score every .pos against the scenario's truth.csv with bench_eval_pos (canyon::eval): fix rate (fixed epochs /
# rover epochs), 3D RMSE and maximum 3D error over all solved epochs, wrong fixes (fixed, 3D error > 0.10 m).
#
# Usage: tests/bench/sim_vs_rtklib.sh [BUILD_DIR] [SEEDS] [SCENARIOS...]
#   defaults: build, "1", open-sky light-blocked urban-moderate urban-severe
# Environment: KEEP=1 keeps the temp folder and prints its path.
# Exit status: 0 done, 1 a canyon process run failed (its cell says "failed", the other runs go on; listed at the
# end), 2 missing build or tools.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
seeds=${2:-1}
shift $(($# > 2 ? 2 : $#)) || true
scenarios=("$@")
((${#scenarios[@]} > 0)) || scenarios=(open-sky light-blocked urban-moderate urban-severe)
canyon=$build/canyon
eval_pos=$build/tests/bench/bench_eval_pos
conf=$root/config/rtklib/sim.conf

[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
[[ -x $eval_pos ]] || { echo "error: $eval_pos not built (CANYON_BUILD_BENCHMARKS=ON)" >&2; exit 2; }
command -v rnx2rtkp >/dev/null || { echo "error: rnx2rtkp not installed (run scripts/setup.sh)" >&2; exit 2; }

tmp=$(mktemp -d)
if [[ ${KEEP:-0} == 1 ]]; then
  echo "keeping $tmp"
else
  trap 'rm -rf "$tmp"' EXIT
fi
sed 's/^pos1-ionoopt .*/pos1-ionoopt       =brdc/' "$conf" >"$tmp/rtklib-brdc.conf"

# Value of key $2 in a bench_eval_pos --kv line $1, "-" if absent.
kv() { tr ' ' '\n' <<<"$1" | awk -F= -v k="$2" '$1 == k {print $2; found = 1} END {if (!found) print "-"}'; }
# "fix% rmse max wrong" of a .pos file against the truth.
score() {
  local pos=$1 dir=$2 line max
  line=$("$eval_pos" "$pos" --truth "$dir/truth.csv" --epochs-in "$(grep -c '^> ' "$dir/rover.obs")" --kv)
  max=$("$eval_pos" "$pos" --truth "$dir/truth.csv" | awk '$1 == "all" {print $9}')
  printf '%s %s %s %s' "$(kv "$line" fixed_pct)" "$(kv "$line" rmse_3d_m)" "${max:--}" "$(kv "$line" wrong_fixes)"
}

printf '%-15s %4s %6s %6s | %-28s | %-28s | %-28s | %-28s\n' scenario seed gen_s nlos% \
  "RTKLIB est-stec fix/rmse/max" "RTKLIB brdc fix/rmse/max" "canyon rtk-urban fix/rmse/max" "canyon rtk.yaml fix/rmse/max"
failed=()
for scenario in "${scenarios[@]}"; do
  for seed in $seeds; do
    dir=$tmp/$scenario-$seed
    start=$(date +%s.%N)
    summary=$("$canyon" simulate --scenario "$scenario" --seed "$seed" --out "$dir" 2>&1)
    gen_s=$(awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN {printf "%.2f", e - s}')
    nlos=$(sed -n 's/.*(\([0-9.]*\) % NLOS).*/\1/p' <<<"$summary")
    rnx2rtkp -k "$conf" -o "$dir/rtklib.pos" "$dir/rover.obs" "$dir/base.obs" "$dir/nav.rnx" >/dev/null 2>&1
    rnx2rtkp -k "$tmp/rtklib-brdc.conf" -o "$dir/rtklib-brdc.pos" "$dir/rover.obs" "$dir/base.obs" "$dir/nav.rnx" \
      >/dev/null 2>&1
    "$canyon" process -q --mode rtk --config "$root/config/rtk-urban.yaml" --rover "$dir/rover.obs" --base "$dir/base.obs" \
      --nav "$dir/nav.rnx" --out "$dir/canyon.pos" >"$dir/canyon.log" 2>&1 ||
      failed+=("$scenario seed $seed: canyon rtk-urban ($(tail -n 1 "$dir/canyon.log"))")
    "$canyon" process -q --mode rtk --config "$root/config/rtk.yaml" --rover "$dir/rover.obs" --base "$dir/base.obs" \
      --nav "$dir/nav.rnx" --out "$dir/canyon-default.pos" >"$dir/canyon-default.log" 2>&1 ||
      failed+=("$scenario seed $seed: canyon rtk.yaml ($(tail -n 1 "$dir/canyon-default.log"))")
    cells=()
    for pos in rtklib rtklib-brdc canyon canyon-default; do
      if [[ -s $dir/$pos.pos ]]; then
        read -r fix rmse max wrong <<<"$(score "$dir/$pos.pos" "$dir")"
        cells+=("$(printf '%5s%% %8s m %8s m w%s' "$fix" "$rmse" "$max" "$wrong")")
      else
        cells+=("failed")
      fi
    done
    printf '%-15s %4s %6s %6s | %-28s | %-28s | %-28s | %-28s\n' "$scenario" "$seed" "$gen_s" "$nlos" "${cells[@]}"
  done
done
echo "fix = fixed epochs / rover epochs; rmse, max = 3D error of all solved epochs against truth.csv; w = wrong fixes"
echo "(fixed, 3D error > 0.10 m); gen_s = wall time of canyon simulate; nlos% = rover signals received only by reflection."
if ((${#failed[@]} > 0)); then
  printf 'FAILED: %s\n' "${failed[@]}"
  exit 1
fi
