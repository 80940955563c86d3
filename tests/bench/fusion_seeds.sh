#!/usr/bin/env bash
# Issue 5's urban-severe targets over many seeds: for each seed, canyon simulate, RTKLIB 2.4.3 (rnx2rtkp -k
# config/rtklib/sim.conf) and canyon fusion (config/fusion.yaml or CONFIG), both scored by canyon evaluate; one line per
# seed (3D RMSE, availability, fixed epochs and wrong fixes, RTKLIB's RMSE and availability, whether fusion's RMSE <=
# 1/5 of RTKLIB's) and a tally: seeds with a solution at every epoch, seeds meeting the RMSE ratio, median RMSE, fixed
# epochs and wrong fixes (3D error > 0.10 m).
# Usage: tests/bench/fusion_seeds.sh [BUILD_DIR] [FIRST] [LAST] [SCENARIO] [CONFIG]
#   defaults: build, 1, 30, urban-severe, config/fusion.yaml. KEEP=1 keeps the temp folder and prints its path.
# Exit status: 0 done, 1 a step failed (rnx2rtkp, canyon process or evaluate: its seed's line says "no evaluation"
# or lacks the figure, the other seeds still run; the failed steps are listed at the end), 2 missing build or tools.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
first=${2:-1}
last=${3:-30}
scenario=${4:-urban-severe}
config=$(realpath "${5:-$root/config/fusion.yaml}")
canyon=$build/canyon

[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
command -v rnx2rtkp >/dev/null || { echo "error: rnx2rtkp not installed (run scripts/setup.sh)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "error: python3 needed to read the evaluations" >&2; exit 2; }

tmp=$(mktemp -d)
: >"$tmp/seeds.tsv"
if [[ ${KEEP:-0} == 1 ]]; then
  echo "keeping $tmp"
else
  trap 'rm -rf "$tmp"' EXIT
fi

failed=()
for ((seed = first; seed <= last; ++seed)); do
  dir=$tmp/$scenario-$seed
  "$canyon" simulate -q --scenario "$scenario" --seed "$seed" --out "$dir"
  rnx2rtkp -k "$root/config/rtklib/sim.conf" -o "$dir/rtklib.pos" "$dir/rover.obs" "$dir/base.obs" "$dir/nav.rnx" \
    >/dev/null 2>&1 || failed+=("seed $seed: rnx2rtkp")
  "$canyon" process -q --config "$config" --rover "$dir/rover.obs" --base "$dir/base.obs" --nav "$dir/nav.rnx" \
    --vio "$dir/vio.csv" --timesync "$dir/timesync.csv" --out "$dir/fusion.pos" 2>"$dir/fusion.log" ||
    failed+=("seed $seed: canyon process (fusion)")
  "$canyon" evaluate -q --truth "$dir/truth.csv" --rover "$dir/rover.obs" --solution "$dir/rtklib.pos" \
    --label RTKLIB --solution "$dir/fusion.pos" --label fusion --json "$dir/evaluation.json" ||
    failed+=("seed $seed: canyon evaluate")
  python3 - "$dir/evaluation.json" "$seed" "$tmp/seeds.tsv" <<'PY'
import json, sys
path, seed, table = sys.argv[1:4]
try:
    solutions = {s["label"]: s for s in json.load(open(path))["solutions"]}
except (OSError, ValueError, KeyError):
    print("seed %s: no evaluation" % seed)
    sys.exit(0)
def figures(label):
    s = solutions.get(label)
    if not s or not s["ape"]["all"]["3d"]:
        return float("nan"), 0.0
    return s["ape"]["all"]["3d"]["rmse_m"], s["availability"]
f, fa = figures("fusion")
r, ra = figures("RTKLIB")
fusion = solutions.get("fusion", {})
fixed, wrong = fusion.get("status", {}).get("fixed", {}).get("epochs", 0), fusion.get("wrong_fixes", 0)
every, ratio = fa >= 1.0 - 1e-9, f <= r / 5
print("seed %3s: fusion %8.2f m, %6.2f %%, fixed %5d, wrong %5d | RTKLIB %8.2f m, %6.2f %% | every epoch: %-3s | "
      "RMSE <= 1/5 RTKLIB: %s" % (seed, f, 100 * fa, fixed, wrong, r, 100 * ra, "yes" if every else "no",
                                  "yes" if ratio else "no"))
with open(table, "a") as out:
    out.write("%s\t%r\t%d\t%d\t%d\t%d\n" % (seed, f, every, ratio, fixed, wrong))
PY
done
python3 - "$tmp/seeds.tsv" <<'PY'
import math, statistics, sys
rows = [line.split("\t") for line in open(sys.argv[1])]
rmse = [float(r[1]) for r in rows if not math.isnan(float(r[1]))]
fixed, wrong = sum(int(r[4]) for r in rows), sum(int(r[5]) for r in rows)
print("%d seeds: a solution at every epoch on %d, RMSE <= 1/5 of RTKLIB's on %d, median fusion RMSE %.1f m; "
      "fusion fixed %d epochs, %d of them wrong (3D error > 0.10 m)"
      % (len(rows), sum(int(r[2]) for r in rows), sum(int(r[3]) for r in rows),
         statistics.median(rmse) if rmse else float("nan"), fixed, wrong))
PY
if ((${#failed[@]} > 0)); then
  printf 'FAILED: %s\n' "${failed[@]}"
  exit 1
fi
