#!/usr/bin/env bash
# Compares two folders written by tests/bench/solutions_digest.sh (a baseline and a candidate build): how many
# outputs are byte for byte identical, and for each solution that differs its epochs by status in both (Q 1 fixed,
# 2 float, 5 single, 7 VIO fill-in), then the rows of the benches' own tables (rtk_vs_rtklib: fix rate, 3D RMSE,
# wrong fixes; fusion_vs_rtklib: fix rate, availability, wrong fixes, 3D RMSE per scenario, seed, ablation and
# instinct run) that differ, timing columns left out.
# Usage: tests/bench/solutions_compare.sh BASELINE_DIR CANDIDATE_DIR
set -uo pipefail
a=${1:?usage: solutions_compare.sh BASELINE_DIR CANDIDATE_DIR}
b=${2:?usage: solutions_compare.sh BASELINE_DIR CANDIDATE_DIR}
[[ -f $a/digest.txt && -f $b/digest.txt ]] || { echo "error: no digest.txt in $a or $b" >&2; exit 2; }

joined=$(join -j 2 <(sort -k2 "$a/digest.txt") <(sort -k2 "$b/digest.txt"))
total=$(wc -l <<< "$joined")
different=$(awk '$2 != $3 {print $1}' <<< "$joined")
echo "outputs compared: $total, identical: $((total - $(grep -c . <<< "$different"))), only in one: $(join -v1 -v2 -j 2 \
  <(sort -k2 "$a/digest.txt") <(sort -k2 "$b/digest.txt") | wc -l)"

# status_counts FILE: "fixed float single fill-in" epochs of a .pos file.
status_counts() {
  awk '!/^%/ && NF >= 6 {q[$6]++} END {printf "%5d %5d %5d %5d", q[1], q[2], q[5], q[7]}' "$1"
}
if [[ -n $different ]]; then
  printf '\n%-62s %-23s   %-23s\n' "solution (epochs: fixed float single fill-in)" baseline candidate
  while IFS= read -r file; do
    [[ $file == *.pos ]] || { echo "$file differs"; continue; }
    printf '%-62s %s   %s\n' "$file" "$(status_counts "$a/$file")" "$(status_counts "$b/$file")"
  done <<< "$different"
fi

# The benches' table rows that differ (the timing columns are cut: they differ from run to run).
for log in rtk fusion; do
  [[ -f $a/$log.log && -f $b/$log.log ]] || continue
  cut_timing() {
    if [[ $log == rtk ]]; then awk 'NF >= 10 && $NF ~ /x$/ {NF -= 3; print}' "$1"; else sed -E 's/\|[^|]*[0-9.]+x *$//; s/\| *[0-9.]+ +[0-9.]+ *$//' "$1" | grep '|'; fi
  }
  rows=$(diff <(cut_timing "$a/$log.log") <(cut_timing "$b/$log.log") | grep '^[<>]')
  [[ -z $rows ]] && continue
  echo
  echo "$log bench rows that differ (< baseline, > candidate):"
  echo "$rows"
done
