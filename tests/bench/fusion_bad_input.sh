#!/usr/bin/env bash
# Fusion on bad VIO and time-sync input (issue 28's bad-input list), on a generated scenario: the VIO jumps 100 m
# mid-walk, stops for 30 s, reports a covariance 3x too small, has a 0.5 % scale error; the time-sync stream steps by
# 1 s mid-walk. Each against the clean run of the same seed: correct fixes (within 10 cm of the truth, over all
# epochs), wrong fixes, the horizontal error over the last 60 s (the track recovers), and what the log said.
#
# Usage: tests/bench/fusion_bad_input.sh [BUILD_DIR] [SCENARIO] [SEEDS] [DURATION_S]
#        (defaults: build, light-blocked, "1 2 3", 300)
# Environment: KEEP=1 keeps the temp folder. Exit 0 when no bad input causes a wrong fix that the clean run does not
# have and every run ends within 1 m horizontally, 1 otherwise, 2 missing build.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
scenario=${2:-light-blocked}
seeds=${3:-1 2 3}
duration=${4:-300}
canyon=$build/canyon
[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
tmp=$(mktemp -d)
if [[ ${KEEP:-0} == 1 ]]; then echo "keeping $tmp"; else trap 'rm -rf "$tmp"' EXIT; fi
src=$root/config/scenarios/$scenario.yaml
[[ -f $src ]] || { echo "error: no scenario $src" >&2; exit 2; }

# A scenario variant with one vio key changed.
variant() { sed "s/^  $1: [^ ]* /  $1: $2 /" "$src" > "$tmp/$3.yaml"; grep -q "^  $1: $2 " "$tmp/$3.yaml"; }
variant covariance_optimism 1.7320508 optimistic   # covariance 3x too small: sigmas / sqrt(3)
variant scale_error 0.005 scaled

# Device time (ns) of the VIO's middle pose.
middle_ns() { awk -F, 'NR > 1 {t[NR] = $1} END {print t[int(NR / 2)]}' "$1"; }

# Fuse and score: "correct wrong last60_max_h_m".
score() {
  local d=$1 vio=$2 sync=$3 out=$4
  "$canyon" process --config "$root/config/fusion.yaml" --rover "$d/rover.obs" --base "$d/base.obs" \
    --nav "$d/nav.rnx" --vio "$vio" --timesync "$sync" --out "$out.pos" > /dev/null 2> "$out.log" || true
  "$canyon" evaluate --truth "$d/truth.csv" --solution "$out.pos" --label x --rover "$d/rover.obs" \
    --out-dir "$out.eval" > "$out.txt" 2>&1 || true
  local correct wrong last
  correct=$(awk '/^correct fixes/ {print $8}' "$out.txt" | tr -d '()')
  wrong=$(awk '/^wrong fixes/ {print $9}' "$out.txt")
  # The last 60 s: the largest horizontal error (the track has recovered).
  awk '/^%/ {print; next} {t[NR] = $2; line[NR] = $0} END {for (i in t) if (t[i] >= max) max = t[i];
       for (i = 1; i <= NR; i++) if (i in t && t[i] >= max - 60) print line[i]}' "$out.pos" > "$out.last60.pos"
  "$canyon" evaluate --truth "$d/truth.csv" --solution "$out.last60.pos" --label x > "$out.last60.txt" 2>&1 || true
  last=$(awk '/^APE horizontal, all epochs/ {f = 1} f && $1 == "max" {print $2; exit}' "$out.last60.txt")
  echo "${correct:-?} ${wrong:-?} ${last:-?}"
}

printf '%-14s %5s %-24s %9s %6s %12s  %s\n' scenario seed input "correct%" wrong "last 60 s m" "log"
failed=0
for seed in $seeds; do
  d=$tmp/$seed
  "$canyon" simulate -q --scenario "$src" --seed "$seed" --duration "$duration" --out "$d/clean"
  "$canyon" simulate -q --scenario "$tmp/optimistic.yaml" --seed "$seed" --duration "$duration" --out "$d/optimistic"
  "$canyon" simulate -q --scenario "$tmp/scaled.yaml" --seed "$seed" --duration "$duration" --out "$d/scaled"
  c=$d/clean
  mid=$(middle_ns "$c/vio.csv")
  awk -F, -v OFS=, -v m="$mid" 'NR > 1 && $1 >= m {$2 = sprintf("%.6f", $2 + 100)} 1' "$c/vio.csv" > "$d/vio-jump.csv"
  awk -F, -v m="$mid" 'NR == 1 || $1 < m || $1 >= m + 30e9' "$c/vio.csv" > "$d/vio-stop.csv"
  awk -F, -v OFS=, -v m="$mid" 'NR > 1 && $1 >= m {$1 = sprintf("%.0f", $1 + 1e9)} 1' "$c/timesync.csv" > "$d/sync-step.csv"
  read -r clean_correct clean_wrong clean_last <<<"$(score "$c" "$c/vio.csv" "$c/timesync.csv" "$d/r-clean")"
  printf '%-14s %5s %-24s %9s %6s %12s\n' "$scenario" "$seed" clean "$clean_correct" "$clean_wrong" "$clean_last"
  for input in jump stop optimistic scaled sync-step; do
    case $input in
      jump) r=$(score "$c" "$d/vio-jump.csv" "$c/timesync.csv" "$d/r-$input"); what="VIO +100 m mid-walk" ;;
      stop) r=$(score "$c" "$d/vio-stop.csv" "$c/timesync.csv" "$d/r-$input"); what="VIO stops 30 s" ;;
      optimistic) r=$(score "$d/optimistic" "$d/optimistic/vio.csv" "$d/optimistic/timesync.csv" "$d/r-$input")
        what="VIO covariance 3x small" ;;
      scaled) r=$(score "$d/scaled" "$d/scaled/vio.csv" "$d/scaled/timesync.csv" "$d/r-$input")
        what="VIO scale +0.5 %" ;;
      sync-step) r=$(score "$c" "$c/vio.csv" "$d/sync-step.csv" "$d/r-$input"); what="time sync 1 s step" ;;
    esac
    read -r correct wrong last <<<"$r"
    said=$(grep -m1 -oE "VIO (gap|jump|covariance reset)[^:]*|device clock steps by [^:]*" "$d/r-$input.log" || true)
    [[ -n $said ]] || said=$(grep -m1 -oE "error: .*" "$d/r-$input.log" || true)
    printf '%-14s %5s %-24s %9s %6s %12s  %s\n' "$scenario" "$seed" "$what" "$correct" "$wrong" "$last" "${said:-}"
    if [[ $wrong != "$clean_wrong" && $wrong != 0 ]]; then failed=1; fi
    if ! awk -v m="$last" 'BEGIN {exit !(m != "?" && m + 0 <= 1.0)}'; then failed=1; fi
  done
done
exit "$failed"
