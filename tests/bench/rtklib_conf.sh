#!/usr/bin/env bash
# RTKLIB option files (rtklib/*.conf of the shared datasets) read as canyon configurations, for the bench scripts that
# run canyon and rnx2rtkp side by side on the same settings (rtk_vs_rtklib.sh, leave_out_check.sh). Sourced, not run.
# write_yaml's keys: see the header of rtk_vs_rtklib.sh.

# Value of an RTKLIB option ("key =value # comment") in a conf file.
conf_value() { awk -v k="$2" '$1 == k || index($0, k " ") == 1 || index($0, k "=") == 1 {
  sub(/^[^=]*=/, ""); sub(/#.*/, ""); gsub(/[ \t]/, ""); print; exit }' "$1"; }

# WGS84 geodetic (deg, deg, m) -> ECEF "x,y,z".
llh_to_ecef() {
  awk -v lat="$1" -v lon="$2" -v h="$3" 'BEGIN {
    a = 6378137.0; f = 1 / 298.257223563; e2 = f * (2 - f); d = atan2(1, 1) / 45;
    sp = sin(lat * d); cp = cos(lat * d); n = a / sqrt(1 - e2 * sp * sp);
    printf "%.4f,%.4f,%.4f\n", (n + h) * cp * cos(lon * d), (n + h) * cp * sin(lon * d), (n * (1 - e2) + h) * sp }'
}

# Base position "x,y,z" as RTKLIB takes it from the conf: xyz, llh, or the base RINEX header (rinexhead).
base_position() {
  local conf=$1 base_obs=$2 type
  type=$(conf_value "$conf" ant2-postype)
  case $type in
    xyz) echo "$(conf_value "$conf" ant2-pos1),$(conf_value "$conf" ant2-pos2),$(conf_value "$conf" ant2-pos3)" ;;
    llh) llh_to_ecef "$(conf_value "$conf" ant2-pos1)" "$(conf_value "$conf" ant2-pos2)" "$(conf_value "$conf" ant2-pos3)" ;;
    rinexhead) awk '/APPROX POSITION XYZ/ {printf "%s,%s,%s\n", $1, $2, $3; exit}' "$base_obs" ;;
    *) echo "error: $conf: ant2-postype '$type' not handled" >&2; return 1 ;;
  esac
}

# canyon's YAML equivalent of an RTKLIB conf (keys: see the header of rtk_vs_rtklib.sh).
write_yaml() {
  local conf=$1 armode frequency navsys systems="" gloar
  armode=$(conf_value "$conf" pos2-armode)
  case $armode in
    continuous) armode=continuous ;;
    instantaneous) armode=instantaneous ;;
    fix-and-hold) armode=fix_and_hold ;;
    *) echo "error: $conf: pos2-armode '$armode' has no canyon equivalent" >&2; return 1 ;;
  esac
  frequency=$(conf_value "$conf" pos1-frequency)
  case $frequency in
    l1) frequency=1 ;;
    l1+2) frequency=2 ;;
    l1+2+3) frequency=3 ;;
    *) echo "error: $conf: pos1-frequency '$frequency' has no canyon equivalent" >&2; return 1 ;;
  esac
  navsys=$(conf_value "$conf" pos1-navsys)
  ((navsys & 1)) && systems+="G, "
  ((navsys & 4)) && systems+="R, "
  ((navsys & 8)) && systems+="E, "
  ((navsys & 32)) && systems+="C, "
  ((navsys & 16)) && systems+="J, "
  gloar=$(conf_value "$conf" pos2-gloarmode)
  [[ $gloar == off ]] || gloar=on
  local tropo=saastamoinen spp_models=""
  if [[ $(conf_value "$conf" pos1-tropopt) == off ]]; then
    tropo=off
    spp_models=$'spp:\n  troposphere: off\n'
  fi
  [[ $(conf_value "$conf" pos1-ionoopt) == off ]] && spp_models=${spp_models:-$'spp:\n'}$'  ionosphere: off\n'
  cat <<YAML
# canyon equivalent of $(basename "$conf") (written by tests/bench/rtklib_conf.sh)
mode: rtk
rtk:
  ar_mode: $armode
  elevation_mask_deg: $(conf_value "$conf" pos1-elmask)
  frequencies: $frequency
  systems: [${systems%, }]
  ratio_threshold: $(conf_value "$conf" pos2-arthres)
  glonass_ar: $gloar
  troposphere: $tropo
YAML
  printf '%s' "$spp_models"
}

