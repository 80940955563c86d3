#!/usr/bin/env bash
# The dashboard in a real browser: canyon-dashboard serves the bundled page while feed.py streams snapshots (with bad
# lines mixed in); headless Chromium opens it and page_probe.py reads the page's counters over the DevTools protocol
# once the history has arrived and again 3 s later: the values must change (more snapshots, a later monitor time) and
# every chart must have drawn pixels; /metrics is checked; a screenshot is kept.
# Usage: browser_test.sh BUILD_DIR [SCREENSHOT.png]
# Exit 77 (skipped, with the reason) without Chromium, python3-websocket or the bundle.
set -euo pipefail

build_dir="$(cd "${1:?usage: $0 BUILD_DIR [SCREENSHOT.png]}" && pwd)"
screenshot="${2:-${build_dir}/dashboard.png}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
chromium="$(command -v chromium || command -v chromium-browser || true)"
if [[ -z "${chromium}" ]]; then
  echo "SKIP: chromium not installed (scripts/setup.sh installs it)"
  exit 77
fi
if ! /usr/bin/python3 -c "import websocket" 2> /dev/null; then
  echo "SKIP: python3-websocket not installed (scripts/setup.sh installs it)"
  exit 77
fi
if [[ ! -x "${build_dir}/canyon-dashboard" || ! -f "${build_dir}/web/dist/app.js" ]]; then
  echo "SKIP: canyon-dashboard or the web bundle not built (cmake --build BUILD --target canyon-dashboard canyon_web)"
  exit 77
fi

work="$(mktemp -d)"
pids=()
cleanup() {
  local pid
  for pid in "${pids[@]}"; do kill "${pid}" 2> /dev/null || true; done
  for pid in "${pids[@]}"; do wait "${pid}" 2> /dev/null || true; done
  rm -rf "${work}"
}
trap cleanup EXIT

mkfifo "${work}/feed"
python3 "${here}/feed.py" --rate 5 --seconds 400 --bad-lines > "${work}/feed" &
pids+=($!)
"${build_dir}/canyon-dashboard" --port 0 --input "${work}/feed" > "${work}/dashboard.log" 2>&1 &
pids+=($!)
port=""
for _ in $(seq 100); do
  port="$(sed -n 's|^canyon-dashboard: http://127.0.0.1:\([0-9]*\)/.*|\1|p' "${work}/dashboard.log")"
  [[ -n "${port}" ]] && break
  sleep 0.1
done
if [[ -z "${port}" ]]; then
  cat "${work}/dashboard.log"
  echo "FAILED: canyon-dashboard did not start"
  exit 1
fi
url="http://127.0.0.1:${port}/"
# The feed first: under ctest -j2 beside the heavy tests its start-up can take seconds. Wait until the dashboard has
# some snapshots (60 s at most), so that the page's first reading includes the history.
snapshots() {
  python3 -c "import urllib.request; print(urllib.request.urlopen('${url}metrics', timeout=5).read().decode())" \
    2> /dev/null | sed -n 's/^canyon_dashboard_snapshots_total \([0-9]*\)/\1/p'
}
deadline=$((SECONDS + 60))
until [[ "$(snapshots)" =~ ^[1-9] ]] || ((SECONDS >= deadline)); do sleep 0.2; done

# One page in Chromium, read over the DevTools protocol twice, 3 s apart: the history arrived, then live snapshots.
if ! timeout --kill-after=5 180 /usr/bin/python3 "${here}/page_probe.py" --chromium "${chromium}" --url "${url}" \
  --profile "${work}/profile" --screenshot "${screenshot}" --gap 3 > "${work}/readings.json"; then
  cat "${work}/dashboard.log"
  echo "FAILED: the page could not be read (above: page_probe's reason, then the dashboard's log)"
  exit 1
fi
# reading WHICH KEY: a counter of #test-status in the first or second reading.
reading() { python3 -c "import json, sys; print(json.load(open(sys.argv[1]))[sys.argv[2]][sys.argv[3]])" \
  "${work}/readings.json" "$1" "$2"; }
updates1="$(reading first updates)"
last1="$(reading first lastT)"
updates2="$(reading second updates)"
last2="$(reading second lastT)"
drawn="$(reading second drawn)"
charts="$(reading second charts)"
echo "first reading: ${updates1} snapshots up to t=${last1} s; 3 s later: ${updates2} up to t=${last2} s;" \
  "charts drawn: ${drawn} of ${charts}"
fail=0
if [[ "${updates2}" -lt 10 || "${updates2}" -le "${updates1}" ]]; then
  echo "FAILED: the page received too few snapshots, or none live"
  fail=1
fi
if ! python3 -c "import sys; sys.exit(0 if float('${last2}') > float('${last1}') else 1)"; then
  echo "FAILED: the monitor time did not advance between the two readings"
  fail=1
fi
protection="$(reading second protection)"
if [[ ! "${protection}" =~ ^[0-9.]+\ /\ [0-9.]+\ m$ ]]; then
  echo "FAILED: the protection level tile shows '${protection}', not 'H / V m'"
  fail=1
fi
if [[ "${charts}" -lt 8 || "${drawn}" != "${charts}" ]]; then
  echo "FAILED: not every chart drew"
  fail=1
fi
metrics="$(python3 -c "import urllib.request; print(urllib.request.urlopen('${url}metrics', timeout=5).read().decode())")"
for want in 'canyon_solution_status ' 'canyon_correction_age_seconds ' 'canyon_stage_latency_us{stage="update",quantile="0.99"}' \
  'canyon_lever_arm_m{axis="x"}' 'canyon_solution_hpl_m ' 'canyon_solution_vpl_m '; do
  if ! grep -qF "${want}" <<< "${metrics}"; then
    echo "FAILED: /metrics has no ${want}"
    fail=1
  fi
done
bad="$(sed -n 's/^canyon_dashboard_bad_lines_total \([0-9]*\)/\1/p' <<< "${metrics}")"
if [[ -z "${bad}" || "${bad}" -lt 1 ]]; then
  echo "FAILED: the bad lines of the feed were not counted"
  fail=1
fi
if [[ ! -s "${screenshot}" ]]; then
  echo "FAILED: no screenshot"
  fail=1
else
  echo "screenshot: ${screenshot}"
fi
if ((fail)); then
  cat "${work}/dashboard.log"
  exit 1
fi
echo "dashboard browser test passed (${bad} bad lines skipped)"
