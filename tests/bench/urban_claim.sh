#!/usr/bin/env bash
# Issue 28's "done when", every figure in one run: per seed of each scenario RTKLIB (its calibrated best set-up of
# config/rtklib/sim.conf), canyon rtk (config/rtk.yaml, unchanged since the issue's frozen baseline) and canyon fusion
# with its defaults (no --config: the recommended set-up, equal to config/fusion.yaml), all scored by canyon evaluate
# against the truth; then VIO at 1 and 2 Hz on downtown, light-blocked with the defaults, the alignment at 180 s
# (bench_repair_truth), and, when asked, the shared real datasets, the ablation table and the bad-input runs.
#
# Usage: tests/bench/urban_claim.sh [BUILD_DIR] [SEEDS] [PARTS]
#   defaults: build, "1 2 3 4 5 6 7 8 9 10" (the development seeds; the held-out ones are 101-130),
#   PARTS "scenarios vio light alignment" (add: real ablation badinput).
# Environment: SCENARIOS (default "downtown downtown-mild downtown-vehicle urban-moderate urban-severe"),
#   KEEP=1 keeps the temp folder.
# Per seed one line per estimator: fix rate, correct-fix rate (fixed within 10 cm 3D of the truth, over all
# epochs), wrong fixes (and their share of fixed epochs), availability, horizontal RMSE, the largest horizontal
# error from 120 s after the start, the share of epochs beyond 3 sigma (horizontal), the CPU time. Per scenario a
# summary with the issue's criteria. Exit 0 done (targets met or not: the lines say; so do the real-data, ablation
# and bad-input scripts' own verdicts), 1 a run failed, 2 missing build or tools.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
seeds=${2:-1 2 3 4 5 6 7 8 9 10}
parts=${3:-scenarios vio light alignment}
scenarios=${SCENARIOS:-downtown downtown-mild downtown-vehicle urban-moderate urban-severe}
canyon=$build/canyon
[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
command -v rnx2rtkp >/dev/null || { echo "error: rnx2rtkp not installed (run scripts/setup.sh)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "error: python3 needed to read the evaluations" >&2; exit 2; }
tmp=$(mktemp -d)
if [[ ${KEEP:-0} == 1 ]]; then echo "keeping $tmp"; else trap 'rm -rf "$tmp"' EXIT; fi
has_part() { [[ " $parts " == *" $1 "* ]]; }

# RTKLIB's best set-up per scenario (the most correct fixes on seeds 1-10, tests/bench/calibrate_rtklib.sh;
# docs/results/urban-claim.md): the ionosphere option and GLONASS AR.
rtklib_setup() {
  case $1 in
    downtown-vehicle) echo "est-stec on" ;;
    downtown | downtown-mild) echo "est-stec off" ;;
    *) echo "" ;;  # sim.conf as shipped
  esac
}
rtklib_conf() {
  local setup out=$tmp/rtklib-$1.conf
  setup=$(rtklib_setup "$1")
  if [[ -z $setup ]]; then cp "$root/config/rtklib/sim.conf" "$out"; else
    read -r iono glo <<<"$setup"
    sed -e "s|^pos1-ionoopt .*|pos1-ionoopt       =$iono|" -e "s|^pos2-gloarmode .*|pos2-gloarmode     =$glo|" \
      "$root/config/rtklib/sim.conf" > "$out"
  fi
  echo "$out"
}

# `timed LOG CPUFILE CMD...`: runs CMD with its stderr in LOG and appends its CPU seconds (user + system) to CPUFILE.
timed() {
  local log=$1 cpu=$2
  shift 2
  local TIMEFORMAT='%3U %3S'
  { time "$@" 2> "$log" > /dev/null; } 2> "$cpu.t"
  awk '{print $1 + $2}' "$cpu.t" >> "$cpu"
}

# One seed of one scenario (a scenario name or FILE.yaml): simulate, the three estimators, evaluate; a TSV row per
# estimator in $tmp/rows.tsv: scenario seed estimator fixed% correct% wrong fixed_epochs availability rmse_h max_h_120
# beyond3s% cpu_s. LABEL names the scenario in the rows.
run_seed() {
  local scenario=$1 label=$2 seed=$3 estimators=$4 d=$tmp/$2/$3
  mkdir -p "$d"
  if ! "$canyon" simulate -q --scenario "$scenario" --seed "$seed" --out "$d" 2> "$d/simulate.log"; then
    echo "$label seed $seed: canyon simulate failed: $(head -c 300 "$d/simulate.log")"
    return 1
  fi
  local sols=() labels=() est
  for est in $estimators; do
    case $est in
      rtklib) timed "$d/rtklib.log" "$d/rtklib.cpu" rnx2rtkp -k "$(rtklib_conf "$label")" -o "$d/rtklib.pos" \
                "$d/rover.obs" "$d/base.obs" "$d/nav.rnx" ;;
      rtk) timed "$d/rtk.log" "$d/rtk.cpu" "$canyon" process -q --mode rtk --config "$root/config/rtk.yaml" \
             --rover "$d/rover.obs" --base "$d/base.obs" --nav "$d/nav.rnx" --out "$d/rtk.pos" ;;
      fusion) timed "$d/fusion.log" "$d/fusion.cpu" "$canyon" process -q --mode fusion --rover "$d/rover.obs" \
                --base "$d/base.obs" --nav "$d/nav.rnx" --vio "$d/vio.csv" --timesync "$d/timesync.csv" \
                --out "$d/fusion.pos" ;;
    esac || { echo "$label seed $seed: $est failed: $(tail -c 300 "$d/$est.log")"; return 1; }
    sols+=(--solution "$d/$est.pos")
    labels+=(--label "$est")
  done
  "$canyon" evaluate -q --truth "$d/truth.csv" --rover "$d/rover.obs" "${sols[@]}" "${labels[@]}" \
    --json "$d/evaluation.json" > /dev/null 2> "$d/evaluate.log" ||
    { echo "$label seed $seed: canyon evaluate failed: $(head -c 300 "$d/evaluate.log")"; return 1; }
  python3 - "$d" "$label" "$seed" "$tmp/rows.tsv" <<'PY'
import json, math, sys
d, label, seed, table = sys.argv[1:5]
A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)
def ecef(lat, lon, h):
    lat, lon = math.radians(lat), math.radians(lon)
    n = A / math.sqrt(1 - E2 * math.sin(lat) ** 2)
    return ((n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
            (n * (1 - E2) + h) * math.sin(lat))
def horizontal(dx, x):
    lon = math.atan2(x[1], x[0])
    lat = math.atan2(x[2], math.hypot(x[0], x[1]))
    east = -math.sin(lon) * dx[0] + math.cos(lon) * dx[1]
    north = (-math.sin(lat) * math.cos(lon) * dx[0] - math.sin(lat) * math.sin(lon) * dx[1]
             + math.cos(lat) * dx[2])
    return math.hypot(east, north)
truth = {}
for line in open(d + "/truth.csv"):
    if line[0].isdigit():
        f = line.split(",")
        truth[round(float(f[1]) * 1000)] = tuple(map(float, f[2:5]))
start = min(truth) / 1000.0
ev = json.load(open(d + "/evaluation.json"))
for s in ev["solutions"]:
    est = s["label"]
    worst = 0.0
    for line in open(d + "/" + est + ".pos"):
        if line.startswith("%") or not line.strip():
            continue
        f = line.split()
        tow = float(f[1])
        t = truth.get(round(tow * 1000))
        if t is None or tow - start < 120.0:
            continue
        x = ecef(float(f[2]), float(f[3]), float(f[4]))
        worst = max(worst, horizontal([x[i] - t[i] for i in range(3)], t))
    epochs = ev["epochs"]["count"]
    fixed = s["status"].get("fixed", {}).get("epochs", 0)
    wrong = s.get("wrong_fixes", 0)
    rmse = (s["ape"]["all"].get("horizontal") or {}).get("rmse_m", float("nan"))
    beyond = 100.0 * s.get("beyond_3_sigma_horizontal", 0) / max(s.get("epochs_with_covariance", 0), 1)
    cpu = float(open(d + "/" + est + ".cpu").read().split()[-1])
    row = (label, seed, est, 100.0 * fixed / epochs, 100.0 * (fixed - wrong) / epochs, wrong, fixed,
           s["availability"], rmse, worst, beyond, cpu)
    print("%-18s seed %4s %-7s fixed %5.1f %%, correct %5.1f %%, wrong %5d of %5d, availability %.3f, "
          "horizontal RMSE %7.3f m, max after 120 s %8.2f m, beyond 3 sigma %5.1f %%, CPU %.2f s" % row)
    with open(table, "a") as out:
        out.write("\t".join(map(str, row)) + "\n")
PY
}

# The issue's criteria per scenario, from the rows.
summarise() {
  python3 - "$tmp/rows.tsv" <<'PY'
import collections, math, statistics, sys
rows = collections.defaultdict(lambda: collections.defaultdict(list))
for line in open(sys.argv[1]):
    f = line.rstrip("\n").split("\t")
    rows[f[0]][f[2]].append(dict(seed=f[1], fixed=float(f[3]), correct=float(f[4]), wrong=int(f[5]),
                                 fixed_n=int(f[6]), avail=float(f[7]), rmse=float(f[8]), max120=float(f[9]),
                                 beyond=float(f[10]), cpu=float(f[11])))
def wrong_ok(r):  # wrong fixes <= 1 % of fixed epochs or <= 5 epochs
    return r["wrong"] <= 5 or r["wrong"] <= 0.01 * r["fixed_n"]
def med(v):
    return statistics.median(v) if v else float("nan")
print()
for scenario, ests in rows.items():
    print("== %s (%d seeds)" % (scenario, len(next(iter(ests.values())))))
    for est, rs in ests.items():
        c = [r["correct"] for r in rs]
        rm = [r["rmse"] for r in rs if not math.isnan(r["rmse"])]
        fixed_all = sum(r["fixed_n"] for r in rs)
        wrong_all = sum(r["wrong"] for r in rs)
        print("  %-7s correct-fix rate median %5.1f %% (lowest %5.1f %%, fix rate median %5.1f %%); wrong %d of %d "
              "fixed (%.2f %%), seeds breaking 1 %%/5 epochs: %d; availability min %.3f; horizontal RMSE median "
              "%.2f m, worst %.2f m; max after 120 s worst %.1f m (seeds > 5 m: %d); beyond 3 sigma median %.1f %%, "
              "worst %.1f %% (seeds > 1 %%: %d); CPU median %.2f s"
              % (est, med(c), min(c), med([r["fixed"] for r in rs]), wrong_all, fixed_all,
                 100.0 * wrong_all / max(fixed_all, 1), sum(not wrong_ok(r) for r in rs), min(r["avail"] for r in rs),
                 med(rm), max(rm) if rm else float("nan"), max(r["max120"] for r in rs),
                 sum(r["max120"] > 5.0 for r in rs), med([r["beyond"] for r in rs]), max(r["beyond"] for r in rs),
                 sum(r["beyond"] > 1.0 for r in rs), med([r["cpu"] for r in rs])))
    def m(est):
        return med([r["correct"] for r in ests[est]]) if est in ests else float("nan")
    def ratio(a, b):
        return a / b if b > 0 else float("inf")
    if "fusion" in ests and "rtklib" in ests and "rtk" in ests:
        print("  fusion / RTKLIB median correct %.2fx, fusion / canyon rtk %.2fx, fusion - canyon rtk %+.1f points; "
              "CPU RTKLIB / fusion (median of seeds) %.1fx"
              % (ratio(m("fusion"), m("rtklib")), ratio(m("fusion"), m("rtk")), m("fusion") - m("rtk"),
                 ratio(med([r["cpu"] for r in ests["rtklib"]]), med([r["cpu"] for r in ests["fusion"]]))))
    if "rtk" in ests:
        rs = ests["rtk"]
        print("  canyon rtk seeds breaking wrong <= 1 %% or <= 5 epochs: %d of %d"
              % (sum(not wrong_ok(r) for r in rs), len(rs)))
PY
}

failed=0
if has_part scenarios; then
  for scenario in $scenarios; do
    for seed in $seeds; do run_seed "$scenario" "$scenario" "$seed" "rtklib rtk fusion" || failed=1; done
  done
fi
if has_part vio; then
  for hz in 1 2; do
    sed "s|^  rate_hz: 10 |  rate_hz: $hz  |" "$root/config/scenarios/downtown.yaml" > "$tmp/downtown-vio${hz}hz.yaml"
    grep -q "^  rate_hz: $hz " "$tmp/downtown-vio${hz}hz.yaml" || { echo "error: no VIO rate key in downtown.yaml"; exit 1; }
    for seed in $seeds; do run_seed "$tmp/downtown-vio${hz}hz.yaml" "downtown-vio-${hz}hz" "$seed" fusion || failed=1; done
  done
fi
if has_part light; then
  for seed in $seeds; do run_seed light-blocked light-blocked "$seed" "rtk fusion" || failed=1; done
fi
[[ -s $tmp/rows.tsv ]] && summarise
if has_part alignment; then
  for scenario in downtown downtown-mild; do
    echo
    echo "== alignment at 180 s, $scenario (bench_repair_truth: heading error, horizontal lever-arm error)"
    # shellcheck disable=SC2086
    "$build/tests/bench/bench_repair_truth" "$root/config/scenarios/$scenario.yaml" $seeds --max-sigma 0 |
      grep '^alignment' || failed=1
  done
fi
if has_part real; then
  echo; echo "== the shared real datasets against RTKLIB (issue 3's figures)"
  bash "$root/tests/bench/rtk_vs_rtklib.sh" "$build" || echo "(rtk_vs_rtklib.sh exit $?)"
  echo; echo "== the leave-out check"
  bash "$root/tests/bench/leave_out_check.sh" "$build" || echo "(leave_out_check.sh exit $?: a dataset fails)"
fi
if has_part ablation; then
  echo; echo "== the ablation table on downtown"
  bash "$root/tests/bench/ablation_table.sh" "$build" "$seeds" || failed=1
fi
if has_part badinput; then
  echo; echo "== bad input on downtown"
  bash "$root/tests/bench/fusion_bad_input.sh" "$build" downtown "$(echo "$seeds" | cut -d' ' -f1-3)" ||
    echo "(fusion_bad_input.sh exit $?: see above)"
fi
exit "$failed"
