#!/usr/bin/env bash
# The leave-out check of fixes on every shared real dataset (issue 28): canyon check-fixes (rtk mode, the settings
# of the dataset's RTKLIB option file, as rtk_vs_rtklib.sh writes them) solves each input, then again with the 1, 2
# and 3 most-observed satellites left out; at the epochs fixed in both, a fix should land within 5 cm of the full
# solution's at >= 95 % of them. rnx2rtkp runs the same option file in the same run, and canyon should fix at least
# half as many epochs as RTKLIB.
#
# Usage: tests/bench/leave_out_check.sh [BUILD_DIR]
# Environment: CANYON_SHARED_DATA_DIR (default ../shared/data), KEEP=1 keeps the temp folder, ONLY=REGEX selects rows,
# EXTRA_YAML=FILE appends its lines to every configuration, whose last section is rtk: indented keys of a candidate
# setting (e.g. "  snr_weighting: true"); a key the configuration has already is an error (duplicate key).
# Output: per dataset the check's table, then one summary row each. Exit 0 when every dataset passes both criteria,
# 1 when one does not or a run fails, 2 missing build or tools, 77 (SKIP:) no shared data.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
data=${CANYON_SHARED_DATA_DIR:-$root/../shared/data}
canyon=$build/canyon
[[ -x $canyon ]] || { echo "error: $canyon not built (run scripts/build.sh)" >&2; exit 2; }
command -v rnx2rtkp >/dev/null || { echo "error: rnx2rtkp not installed (run scripts/setup.sh)" >&2; exit 2; }
[[ -d $data ]] || { echo "SKIP: shared datasets not found at $data"; exit 77; }
data=$(cd "$data" && pwd)
# shellcheck source=tests/bench/rtklib_conf.sh
source "$root/tests/bench/rtklib_conf.sh"

tmp=$(mktemp -d)
if [[ ${KEEP:-0} == 1 ]]; then echo "keeping $tmp"; else trap 'rm -rf "$tmp"' EXIT; fi

# name | dataset folder | conf (in its rtklib/) | rover | base | nav files (|-separated)
instinct="instinct-spirent-rtk-sim"
rows=(
  "cssrlib-static-doy078|cssrlib-static-doy078|rtk_kinematic.conf|SEPT078M1.21O|3034078M1.21O|SEPT078M.21P"
  "matrtklib-static|matrtklib-static|rtk_kinematic.conf|rover.obs|base.obs|base.nav"
  "cssrlib-kinematic-doy265|cssrlib-kinematic-doy265|rtk_kinematic.conf|SEPT265G.21O|3034265G.21O|SEPT2650.21P"
  "m8p-galway-20181004|m8p-galway-20181004|rtk_kinematic_L1_hdr.conf|rinex/20181004_rover-20181004-1532.obs|rinex/20181004_base-20181004-1452.obs|rinex/20181004_base-20181004-1452.nav"
  "instinct-dynamic|$instinct|rtk_kinematic.conf|iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs|iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs|RINEX_GN_Spirent.23N|RINEX_EN_Spirent.23L"
  "hk-klt-f9p-aae6102|hk-klt-f9p-aae6102|rtk_kinematic.conf|rover_20210610.klt1.ublox.f9p.obs|base_hksc1610.obs|hksc1610.nav"
)

fixed_epochs() { awk '!/^%/ && $6 == 1 {n++} END {print n + 0}' "$1"; }

summary=()
failed=0
for entry in "${rows[@]}"; do
  IFS='|' read -r name folder conf_name rover base navs <<<"$entry"
  [[ -z ${ONLY:-} || $name =~ $ONLY ]] || continue
  dir=$data/$folder
  conf=$dir/rtklib/$conf_name
  [[ -f $conf && -f $dir/$rover && -f $dir/$base ]] || { echo "SKIP: $name: files missing in $dir"; exit 77; }
  IFS='|' read -r -a nav_names <<<"$navs"
  navs_abs=() nav_args=()
  for n in "${nav_names[@]}"; do navs_abs+=("$dir/$n"); nav_args+=(--nav "$dir/$n"); done
  out=$tmp/$name
  mkdir -p "$out"
  write_yaml "$conf" > "$out/canyon.yaml"
  [[ -z ${EXTRA_YAML:-} ]] || cat "$EXTRA_YAML" >> "$out/canyon.yaml"
  # Only Q (column 6) is read from either .pos (llh, with calendar or week/tow time).
  if ! rnx2rtkp -k "$conf" -o "$out/rtklib.pos" "$dir/$rover" "$dir/$base" "${navs_abs[@]}" > /dev/null 2>&1; then
    echo "$name: rnx2rtkp failed"; failed=1; continue
  fi
  rtklib_fixed=$(fixed_epochs "$out/rtklib.pos")
  echo "== $name ($conf_name; RTKLIB $rtklib_fixed fixed)"
  status=0
  "$canyon" check-fixes -q --config "$out/canyon.yaml" --rover "$dir/$rover" --base "$dir/$base" "${nav_args[@]}" \
    --base-pos "$(base_position "$conf" "$dir/$base")" --out "$out/canyon.pos" --leave-out 3 \
    --reference "$out/rtklib.pos" > "$out/check.txt" 2> "$out/check.err" || status=$?
  cat "$out/check.txt"
  if ((status != 0 && status != 3)); then
    echo "$name: canyon check-fixes failed (exit $status):"; cat "$out/check.err"; failed=1; continue
  fi
  canyon_fixed=$(fixed_epochs "$out/canyon.pos")
  worst=$(awk '/left out: / {split($0, a, "("); split(a[2], b, " "); if (min == "" || b[1] + 0 < min) min = b[1] + 0}
               END {print min}' "$out/check.txt")
  both=$(awk '/left out: / {for (i = 1; i <= NF; i++) if ($i == "of") {s = s (s ? "/" : "") $(i + 1)}} END {print s}' \
    "$out/check.txt")
  half=$(awk -v c="$canyon_fixed" -v r="$rtklib_fixed" 'BEGIN {print (2 * c >= r) ? "yes" : "no"}')
  verdict=pass
  if ((status == 3)) || [[ $half == no ]]; then verdict=FAIL; failed=1; fi
  summary+=("$(printf '%-26s %8s %8s %14s %17s %12s  %s' "$name" "$canyon_fixed" "$rtklib_fixed" "$both" \
    "$worst" "$half" "$verdict")")
done
echo
printf '%-26s %8s %8s %14s %17s %12s  %s\n' dataset "c fixed" "R fixed" "fixed in both" "worst agree %" ">= R/2" verdict
printf '%s\n' "${summary[@]}"
exit "$failed"
