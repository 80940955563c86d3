#!/usr/bin/env bash
# What an ideal receiver would fix in a scenario: the scenario as shipped, then with reflections.nlos false (a signal a
# building blocks is not received at all: perfect NLOS exclusion), then also with reflections.multipath false (no
# reflection of any kind). Each variant is simulated per seed and processed by RTKLIB 2.4.3 (rnx2rtkp -k
# config/rtklib/sim.conf), canyon rtk (config/rtk-urban.yaml) and canyon fusion (config/fusion.yaml), all scored by
# canyon evaluate: fix rate, wrong fixes (fixed, 3D error > 0.10 m), availability, 3D RMSE. The other keys of the
# scenario stay as shipped, so the variants differ only in what reaches the antenna.
# Usage: tests/bench/fusion_bounds.sh [BUILD_DIR] [SEEDS] [SCENARIO]
#   defaults: build, "1 2 3", urban-severe. KEEP=1 keeps the temp folder and prints its path.
# Exit status: 0 done, 1 a step failed (rnx2rtkp, canyon process or evaluate: its row shows "-" or "no evaluation",
# the other rows still run; the failed steps are listed at the end), 2 missing build or tools.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
seeds=${2:-1 2 3}
scenario=${3:-urban-severe}
canyon=$build/canyon
shipped=$root/config/scenarios/$scenario.yaml

[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
[[ -f $shipped ]] || { echo "error: no scenario $shipped" >&2; exit 2; }
command -v rnx2rtkp >/dev/null || { echo "error: rnx2rtkp not installed (run scripts/setup.sh)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "error: python3 needed to read the evaluations" >&2; exit 2; }

tmp=$(mktemp -d)
if [[ ${KEEP:-0} == 1 ]]; then
  echo "keeping $tmp"
else
  trap 'rm -rf "$tmp"' EXIT
fi

# The variants: the shipped file with its reflections keys switched (each must be found, or the bench would
# silently measure the shipped scenario three times).
cp "$shipped" "$tmp/shipped.yaml"
sed -E 's/^(  nlos:) true /\1 false/' "$shipped" >"$tmp/no-nlos.yaml"
sed -E 's/^(  nlos:) true /\1 false/; s/^(  multipath:) true /\1 false/' "$shipped" >"$tmp/no-reflections.yaml"
grep -q '^  nlos: false' "$tmp/no-nlos.yaml" || { echo "error: no 'nlos: true' key in $shipped" >&2; exit 2; }
grep -q '^  multipath: false' "$tmp/no-reflections.yaml" || {
  echo "error: no 'multipath: true' key in $shipped" >&2
  exit 2
}

printf '%-16s %4s  %-34s  %-34s  %-34s\n' variant seed "RTKLIB: fix (wrong), avail, RMSE" \
  "canyon rtk" "canyon fusion"
failed=()
for variant in shipped no-nlos no-reflections; do
  for seed in $seeds; do
    dir=$tmp/$variant-$seed
    "$canyon" simulate -q --scenario "$tmp/$variant.yaml" --seed "$seed" --out "$dir"
    rnx2rtkp -k "$root/config/rtklib/sim.conf" -o "$dir/rtklib.pos" "$dir/rover.obs" "$dir/base.obs" \
      "$dir/nav.rnx" >/dev/null 2>&1 || failed+=("$variant seed $seed: rnx2rtkp")
    "$canyon" process -q --config "$root/config/rtk-urban.yaml" --rover "$dir/rover.obs" --base "$dir/base.obs" \
      --nav "$dir/nav.rnx" --out "$dir/rtk.pos" 2>"$dir/rtk.log" || failed+=("$variant seed $seed: canyon rtk")
    "$canyon" process -q --config "$root/config/fusion.yaml" --rover "$dir/rover.obs" --base "$dir/base.obs" \
      --nav "$dir/nav.rnx" --vio "$dir/vio.csv" --timesync "$dir/timesync.csv" --out "$dir/fusion.pos" \
      2>"$dir/fusion.log" || failed+=("$variant seed $seed: canyon fusion")
    "$canyon" evaluate -q --truth "$dir/truth.csv" --rover "$dir/rover.obs" --solution "$dir/rtklib.pos" \
      --label RTKLIB --solution "$dir/rtk.pos" --label rtk --solution "$dir/fusion.pos" --label fusion \
      --json "$dir/evaluation.json" || failed+=("$variant seed $seed: canyon evaluate")
    python3 - "$dir/evaluation.json" "$variant" "$seed" <<'PY'
import json, sys
path, variant, seed = sys.argv[1:4]
try:
    solutions = {s["label"]: s for s in json.load(open(path))["solutions"]}
except (OSError, ValueError, KeyError):
    print("%-16s %4s  no evaluation" % (variant, seed))
    sys.exit(0)
def cell(label):
    s = solutions.get(label)
    if not s:
        return "-"
    ape = s["ape"]["all"]["3d"]
    return "%5.1f %% (%4d), %5.1f %%, %7.2f m" % (100 * s["status"]["fixed"]["rate"], s["wrong_fixes"],
                                                   100 * s["availability"], ape["rmse_m"] if ape else float("nan"))
print("%-16s %4s  %-34s  %-34s  %-34s" % (variant, seed, cell("RTKLIB"), cell("rtk"), cell("fusion")))
PY
  done
done
echo "fix = fixed epochs / rover epochs; (wrong) = fixed epochs more than 0.10 m from the truth; avail = epochs with a"
echo "solution; RMSE = 3D over those. no-nlos: reflections.nlos false; no-reflections: also multipath false."
if ((${#failed[@]} > 0)); then
  printf 'FAILED: %s\n' "${failed[@]}"
  exit 1
fi
