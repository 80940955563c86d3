#!/usr/bin/env bash
# Issue 28's ablation table: fusion on a scenario's seeds with config/fusion.yaml as shipped, with each addition that is
# built but off switched on, without pruning, without VIO (canyon rtk with config/rtk.yaml) and the paper's method
# alone (its motion gate, ratio 3, Algorithm 1's pruning, none of canyon's additions); one summary line per row
# (tests/bench/estimator_seeds.sh: median and lowest correct-fix rate, wrong fixes, horizontal RMSE, beyond 3 sigma,
# beyond the protection level), then a Markdown table of them.
# Usage: tests/bench/ablation_table.sh [BUILD_DIR] [SEEDS] [SCENARIO]
#   defaults: build, "1 2 3 4 5 6 7 8 9 10", config/scenarios/downtown.yaml. ROWS="name ..." runs only those rows.
#   Exit 0 done, 1 a row failed, 2 missing build or tools.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
seeds=${2:-1 2 3 4 5 6 7 8 9 10}
scenario=${3:-$root/config/scenarios/downtown.yaml}
[[ -x $build/canyon ]] || { echo "error: $build/canyon not built (run scripts/build.sh)" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# variant NAME SECTION.KEY=VALUE ...: config/fusion.yaml with each key set in its section (replaced where the file has
# it, else added as the section's first key).
variant() {
  local name=$1 file="$tmp/$1.yaml" kv section key value
  shift
  cp "$root/config/fusion.yaml" "$file"
  for kv in "$@"; do
    section=${kv%%.*}
    kv=${kv#*.}
    key=${kv%%=*}
    value=${kv#*=}
    python3 - "$file" "$section" "$key" "$value" <<'PY'
import re, sys
path, section, key, value = sys.argv[1:]
lines = open(path).read().split("\n")
start = next((i for i, l in enumerate(lines) if l.startswith(section + ":")), None)
if start is None:
    sys.exit(f"error: no section {section} in config/fusion.yaml")
end = next((i for i in range(start + 1, len(lines)) if lines[i] and not lines[i].startswith((" ", "#"))), len(lines))
for i in range(start + 1, end):
    if re.match(rf"  {re.escape(key)}:", lines[i]):
        lines[i] = f"  {key}: {value}"
        break
else:
    lines.insert(start + 1, f"  {key}: {value}")
open(path, "w").write("\n".join(lines))
PY
  done
}

variant shipped
variant slip-repair rtk.ambiguity_prior_max_sigma_cyc=0.15
variant slip-repair-and-reacquisition rtk.ambiguity_prior_max_sigma_cyc=0.15 rtk.iono_max_outage_s=60
variant ionosphere-from-others rtk.iono_residual_sigma_per_10km_m=0.005
variant cascaded-partial-hold rtk.partial_hold_sigma_cyc=0.2
variant code-multipath-states rtk.code_multipath_sigma_m=0.5 rtk.code_multipath_correlation_s=60
variant no-nlos-gate fusion.gate_nlos_sigmas=0
variant no-pruning fusion.gate=off rtk.partial_ar=false
variant paper-alone fusion.gate=paper fusion.gate_nlos_sigmas=0 fusion.coarse_alignment=false fusion.heading_state=false \
  fusion.vio_sigma_factor=1 fusion.vio_scale_state=false fusion.vio_stitch_resets=false fusion.vio_max_bridged_gap_s=0 \
  fusion.false_fix_guard=false fusion.max_fix_sigma_m=1000 fusion.max_prior_rejections=1000000 \
  fusion.integrity_check=false fusion.heading_free_fill_in=false fusion.output_sigma_floor_h_m=0 \
  fusion.output_sigma_floor_v_m=0 fusion.output_unfixed_sigma_factor=1 fusion.cn0_screen=false \
  rtk.snr_weighting=false rtk.ambiguity_noise_cyc=0.0001 rtk.iono_noise_m=0.001 rtk.float_consistency_level=0 \
  rtk.min_success_rate=0

declare -A what=(
  [shipped]="config/fusion.yaml as shipped (every addition below off)"
  [slip-repair]="+ slip repair: a slipped or new ambiguity started from the held position (0.15 cycles)"
  [slip-repair-and-reacquisition]="+ ... and the ionosphere states kept 60 s, so re-acquired signals start so too"
  [ionosphere-from-others]="+ a new ionosphere state from the others' (0.005 m per 10 km)"
  [cascaded-partial-hold]="+ cascaded partial fixing held in the filter (0.2 cycles)"
  [code-multipath-states]="+ time-correlated code multipath states (0.5 m, 60 s)"
  [no-nlos-gate]="without NLOS by VIO consistency (gate_nlos_sigmas 0)"
  [no-pruning]="without pruning (no gate, no ILS pruning)"
  [canyon-rtk]="without VIO: canyon rtk (config/rtk.yaml)"
  [paper-alone]="the paper's method alone (5x motion gate, ratio 3, Algorithm 1, no additions)"
)
rows=${ROWS:-shipped slip-repair slip-repair-and-reacquisition ionosphere-from-others cascaded-partial-hold code-multipath-states no-nlos-gate no-pruning canyon-rtk paper-alone}
failed=0
: >"$tmp/table.md"
for row in $rows; do
  if [[ $row == canyon-rtk ]]; then
    args=("$build" "$root/config/rtk.yaml" "$seeds" "$scenario" rtk)
  else
    args=("$build" "$tmp/$row.yaml" "$seeds" "$scenario" fusion)
  fi
  if ! line=$("$root/tests/bench/estimator_seeds.sh" "${args[@]}" | tail -1); then
    echo "$row: failed"
    failed=1
    continue
  fi
  echo "$row: ${line#*: }"
  printf '| %s | %s |\n' "${what[$row]}" "${line#*seeds: }" >>"$tmp/table.md"
done
echo
echo "| $(basename "$scenario" .yaml), seeds $seeds | result |"
echo "|---|---|"
cat "$tmp/table.md"
exit $failed
