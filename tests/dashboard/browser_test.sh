#!/usr/bin/env bash
# The dashboard in a real browser: canyon-dashboard serves the bundled page while feed.py streams snapshots (with bad
# lines mixed in); headless Chromium loads it twice a few seconds apart and the test asserts that the values change
# (more snapshots, a later monitor time) and that every chart drew pixels; /metrics is checked; a screenshot is kept.
# Usage: browser_test.sh BUILD_DIR [SCREENSHOT.png]     exit 77 (skipped, with the reason) without Chromium or bundle.
set -euo pipefail

build_dir="$(cd "${1:?usage: $0 BUILD_DIR [SCREENSHOT.png]}" && pwd)"
screenshot="${2:-${build_dir}/dashboard.png}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
chromium="$(command -v chromium || command -v chromium-browser || true)"
if [[ -z "${chromium}" ]]; then
  echo "SKIP: chromium not installed (scripts/setup.sh installs it)"
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
browser=("${chromium}" --headless=new --no-sandbox --disable-gpu --disable-dev-shm-usage --hide-scrollbars
  --user-data-dir="${work}/profile")

# status KEY: a data attribute of #test-status in the page as Chromium rendered it.
attr() { sed -n "s|.*<span id=\"test-status\"[^>]* data-$1=\"\([^\"]*\)\".*|\1|p" "${work}/dom.html" | head -1; }
# The DOM after a few seconds of the page; on a busy machine Chromium may need longer to start: up to 4 tries.
load() {
  local budget_ms
  for budget_ms in 5000 10000 20000 40000; do
    timeout 90 "${browser[@]}" --timeout="${budget_ms}" --dump-dom "${url}" 2> /dev/null > "${work}/dom.html" || true
    if [[ "$(attr updates)" =~ ^[1-9] ]]; then return 0; fi
  done
}

# The feed first: under ctest -j2 beside the heavy tests its start-up took long enough for every try of the first
# load to find no snapshot yet (2026-11-25). Wait until the dashboard has some (60 s at most).
snapshots() {
  python3 -c "import urllib.request; print(urllib.request.urlopen('${url}metrics', timeout=5).read().decode())" \
    2> /dev/null | sed -n 's/^canyon_dashboard_snapshots_total \([0-9]*\)/\1/p'
}
deadline=$((SECONDS + 60))
until [[ "$(snapshots)" =~ ^[1-9] ]] || ((SECONDS >= deadline)); do sleep 0.2; done
sleep 2
load
updates1="$(attr updates)"
last1="$(attr last-t)"
sleep 3
load
updates2="$(attr updates)"
last2="$(attr last-t)"
drawn="$(attr drawn)"
charts="$(attr charts)"
echo "first load: ${updates1:-?} snapshots up to t=${last1:-?} s; second load: ${updates2:-?} up to t=${last2:-?} s;" \
  "charts drawn: ${drawn:-?} of ${charts:-?}"
fail=0
if [[ -z "${updates2}" || "${updates2}" -lt 10 ]]; then
  echo "FAILED: the page received too few snapshots"
  fail=1
fi
if [[ -z "${last1}" || -z "${last2}" ]] || ! python3 -c "import sys; sys.exit(0 if float('${last2}') > float('${last1}') else 1)"; then
  echo "FAILED: the monitor time did not advance between the two loads"
  fail=1
fi
if [[ -z "${charts}" || "${charts}" -lt 8 || "${drawn}" != "${charts}" ]]; then
  echo "FAILED: not every chart drew"
  fail=1
fi
metrics="$(python3 -c "import urllib.request; print(urllib.request.urlopen('${url}metrics', timeout=5).read().decode())")"
for want in 'canyon_solution_status ' 'canyon_correction_age_seconds ' 'canyon_stage_latency_us{stage="update",quantile="0.99"}' \
  'canyon_lever_arm_m{axis="x"}'; do
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
timeout 90 "${browser[@]}" --timeout=6000 --window-size=1500,1500 --screenshot="${screenshot}" "${url}" \
  > /dev/null 2>&1 || true
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
