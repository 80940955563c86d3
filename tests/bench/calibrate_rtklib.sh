#!/usr/bin/env bash
# RTKLIB, the independent peer, on a scenario's seeds (issue 28's calibration): config/rtklib/sim.conf unchanged but
# for the four set-ups of broadcast or estimated ionosphere and GLONASS AR off or on; per seed the line-of-sight
# ceiling (epochs with >= 5 satellites tracking phase in line of sight, from canyon simulate) and per set-up the fix
# rate, the correct-fix rate (fixed within 10 cm of the truth, over all epochs) and the wrong fixes. The best set-up
# is the one with the most correct fixes over the seeds; its median correct-fix rate and share of correct fixes are
# what a scenario is calibrated to.
#
# Usage: tests/bench/calibrate_rtklib.sh [BUILD_DIR] [SCENARIO] [SEEDS] [DURATION_S]
#        (defaults: build, urban-moderate, "1 2 3 4 5 6 7 8 9 10", the scenario's duration)
#        SCENARIO: a shipped name or a FILE.yaml.
# Environment: KEEP=1 keeps the temp folder. Exit 0 done, 1 a run failed, 2 missing build or tools.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
scenario=${2:-urban-moderate}
seeds=${3:-1 2 3 4 5 6 7 8 9 10}
duration=${4:-}
canyon=$build/canyon
conf=$root/config/rtklib/sim.conf
[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
command -v rnx2rtkp >/dev/null || { echo "error: rnx2rtkp not installed (run scripts/setup.sh)" >&2; exit 2; }
tmp=$(mktemp -d)
if [[ ${KEEP:-0} == 1 ]]; then echo "keeping $tmp"; else trap 'rm -rf "$tmp"' EXIT; fi

setups=(est-stec/off est-stec/on brdc/off brdc/on)
for s in "${setups[@]}"; do
  sed -e "s|^pos1-ionoopt .*|pos1-ionoopt       =${s%/*}|" -e "s|^pos2-gloarmode .*|pos2-gloarmode     =${s#*/}|" \
    "$conf" > "$tmp/${s//\//-}.conf"
done

median() { sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

printf '%-5s %7s' seed "LOS %"
for s in "${setups[@]}"; do printf ' | %-24s' "$s fix/correct/wrong"; done
printf '\n'
failed=0
declare -A correct_sum fixed_sum wrong_sum rates
for seed in $seeds; do
  d=$tmp/$seed
  args=(simulate --scenario "$scenario" --seed "$seed" --out "$d")
  [[ -z $duration ]] || args+=(--duration "$duration")
  summary=$("$canyon" "${args[@]}" 2>&1) || { echo "seed $seed: canyon simulate failed: $summary"; exit 1; }
  los=$(sed -n 's/.*line-of-sight ceiling \([0-9.]*\) %.*/\1/p' <<<"$summary")
  printf '%-5s %7s' "$seed" "$los"
  for s in "${setups[@]}"; do
    name=${s//\//-}
    if ! rnx2rtkp -k "$tmp/$name.conf" -o "$d/$name.pos" "$d/rover.obs" "$d/base.obs" "$d/nav.rnx" > /dev/null 2>&1; then
      printf ' | %-24s' failed; failed=1; continue
    fi
    "$canyon" evaluate --truth "$d/truth.csv" --solution "$d/$name.pos" --label R --rover "$d/rover.obs" \
      --out-dir "$d/eval-$name" > "$d/eval-$name.txt" 2>&1 || { printf ' | %-24s' "eval failed"; failed=1; continue; }
    fixed=$(awk '/^fixed \(%\)/ {print $3, $4}' "$d/eval-$name.txt")
    correct=$(awk '/^correct fixes/ {print $7, $8}' "$d/eval-$name.txt")
    wrong=$(awk '/^wrong fixes/ {print $9}' "$d/eval-$name.txt")
    read -r nf pf <<<"$fixed"
    read -r nc pc <<<"$correct"
    printf ' | %6s %7s %9s' "${pf//[()]/}" "${pc//[()]/}" "$wrong"
    correct_sum[$s]=$((${correct_sum[$s]:-0} + nc))
    fixed_sum[$s]=$((${fixed_sum[$s]:-0} + nf))
    wrong_sum[$s]=$((${wrong_sum[$s]:-0} + wrong))
    rates[$s]+="${pc//[()]/} "
  done
  printf '\n'
done
best=""
printf '\nset-up        median correct %%   fixed   correct   wrong   correct share of fixes\n'
for s in "${setups[@]}"; do
  med=$(tr ' ' '\n' <<<"${rates[$s]:-}" | grep -v '^$' | median)
  share=$(awk -v c="${correct_sum[$s]:-0}" -v f="${fixed_sum[$s]:-0}" 'BEGIN {printf "%.1f", (f > 0 ? 100 * c / f : 0)}')
  printf '%-13s %16s %7s %9s %7s %10s %%\n' "$s" "$med" "${fixed_sum[$s]:-0}" "${correct_sum[$s]:-0}" \
    "${wrong_sum[$s]:-0}" "$share"
  if [[ -z $best || ${correct_sum[$s]:-0} -gt ${correct_sum[$best]:-0} ]]; then best=$s; fi
done
echo "best set-up (most correct fixes): $best"
exit "$failed"
