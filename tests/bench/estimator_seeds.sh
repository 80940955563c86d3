#!/usr/bin/env bash
# One estimator set-up on a scenario's seeds (issue 28's development runs): per seed canyon simulate, canyon process
# with CONFIG (fusion with the VIO, or --mode rtk without it) and canyon evaluate; one line per seed (fix rate,
# correct-fix rate = fixed within 10 cm (3D) of the truth over all epochs, wrong fixes, horizontal RMSE, availability,
# share of epochs whose horizontal error lies beyond 3 sigma of the output covariance, epochs beyond the protection
# level) and a summary: median and lowest correct-fix rate, wrong fixes in all, seeds with more than 5, median and worst
# horizontal RMSE, median and worst share beyond 3 sigma, epochs beyond the protection level in all.
# Usage: tests/bench/estimator_seeds.sh [BUILD_DIR] [CONFIG] [SEEDS] [SCENARIO] [MODE]
#   defaults: build, config/fusion.yaml, "1 2 3 4 5 6 7 8 9 10", downtown, fusion (rtk: canyon rtk, no VIO).
#   KEEP=1 keeps the temp folder. Exit 0 done, 1 a step failed (its seed says so), 2 missing build or tools.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
config=$(realpath "${2:-$root/config/fusion.yaml}")
seeds=${3:-1 2 3 4 5 6 7 8 9 10}
scenario=${4:-downtown}
mode=${5:-fusion}
canyon=$build/canyon
[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "error: python3 needed to read the evaluations" >&2; exit 2; }
[[ $mode == fusion || $mode == rtk ]] || { echo "error: MODE must be fusion or rtk, not '$mode'" >&2; exit 2; }
tmp=$(mktemp -d)
if [[ ${KEEP:-0} == 1 ]]; then echo "keeping $tmp"; else trap 'rm -rf "$tmp"' EXIT; fi

failed=0
for seed in $seeds; do
  d=$tmp/$seed
  "$canyon" simulate -q --scenario "$scenario" --seed "$seed" --out "$d"
  args=(process -q --mode "$mode" --config "$config" --rover "$d/rover.obs" --base "$d/base.obs" --nav "$d/nav.rnx"
        --out "$d/solution.pos")
  [[ $mode == fusion ]] && args+=(--vio "$d/vio.csv" --timesync "$d/timesync.csv")
  if ! "$canyon" "${args[@]}" 2> "$d/process.log" ||
     ! "$canyon" evaluate -q --truth "$d/truth.csv" --rover "$d/rover.obs" --solution "$d/solution.pos" \
       --label "$mode" --json "$d/evaluation.json" > /dev/null 2>&1; then
    echo "seed $seed: canyon process or evaluate failed: $(head -c 300 "$d/process.log")"
    failed=1
    continue
  fi
  python3 - "$d/evaluation.json" "$seed" "$tmp/seeds.tsv" <<'PY'
import json, sys
path, seed, table = sys.argv[1:4]
s = json.load(open(path))["solutions"][0]
epochs = sum(v["epochs"] for v in s["status"].values())
fixed = s["status"].get("fixed", {}).get("epochs", 0)
wrong = s.get("wrong_fixes", 0)
h = (s["ape"]["all"].get("horizontal") or {}).get("rmse_m", float("nan"))
beyond = 100.0 * s.get("beyond_3_sigma_horizontal", 0) / max(s.get("epochs_with_covariance", 0), 1)
misleading = s.get("beyond_protection_level", 0)
print("seed %4s: fixed %5.1f %%, correct %5.1f %%, wrong %5d, horizontal RMSE %7.3f m, availability %.3f, "
      "beyond 3 sigma %5.1f %%, beyond HPL %4d"
      % (seed, 100.0 * fixed / max(epochs, 1), 100.0 * (fixed - wrong) / max(epochs, 1), wrong, h, s["availability"],
         beyond, misleading))
with open(table, "a") as out:
    out.write("%s\t%r\t%d\t%r\t%r\t%d\n" % (seed, 100.0 * (fixed - wrong) / max(epochs, 1), wrong, h, beyond,
                                             misleading))
PY
done
[[ -s $tmp/seeds.tsv ]] && python3 - "$tmp/seeds.tsv" "$scenario" "$mode" <<'PY'
import math, statistics, sys
rows = [line.split("\t") for line in open(sys.argv[1])]
correct = [float(r[1]) for r in rows]
wrong = [int(r[2]) for r in rows]
h = [float(r[3]) for r in rows if not math.isnan(float(r[3]))]
beyond = [float(r[4]) for r in rows]
print("%s, %s, %d seeds: correct-fix rate median %.1f %% (lowest %.1f %%); %d wrong fixes (%d seeds with more than 5); "
      "horizontal RMSE median %.2f m, worst %.2f m; beyond 3 sigma median %.1f %%, worst %.1f %%; %d epochs beyond HPL"
      % (sys.argv[2], sys.argv[3], len(rows), statistics.median(correct), min(correct), sum(wrong),
         sum(1 for w in wrong if w > 5), statistics.median(h) if h else float("nan"), max(h) if h else float("nan"),
         statistics.median(beyond), max(beyond), sum(int(r[5]) for r in rows)))
PY
exit "$failed"
