#!/usr/bin/env bash
# The one command that sets up and runs canyon's whole test suite from a fresh clone:
#   setup (packages) -> check-format (cheap gate) -> build -> check-tidy -> ctest
# Works from any directory, without a terminal (CI=true, no stdin). Prints each phase's time and, last, the line
#   N passed, N failed
# counted from ctest, where a failed gate (setup, format, build, tidy) counts as one more failure. Exits non-zero on
# any failure. Setup and build failures stop the run (nothing left to test); format and tidy failures do not, so
# one run reports everything.
# Usage: scripts/test.sh [BUILD_DIR]      (default: <repo>/build)
# Environment: CANYON_TIDY_TESTS=1 runs clang-tidy over tests/ too (default: src/ only, to keep CI under 30 minutes).
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$(realpath -m "${1:-${repo_root}/build}")" # absolute: the phases run from the repository root
scripts="${repo_root}/scripts"

passed=0
failed=0
failed_phases=()
timings=()
run_start=${EPOCHREALTIME/[.,]/}

finish() {
  local end=${EPOCHREALTIME/[.,]/}
  echo
  echo "== summary"
  printf '  %s\n' "${timings[@]}"
  printf '  total: %s s\n' "$(elapsed_s "${run_start}" "${end}")"
  if ((${#failed_phases[@]} > 0)); then
    echo "  failed: ${failed_phases[*]}"
  fi
  echo "${passed} passed, ${failed} failed"
  if ((failed > 0)); then exit 1; fi
  exit 0
}

# elapsed_s START_US END_US: seconds with one decimal.
elapsed_s() {
  local us=$(($2 - $1))
  printf '%d.%d' $((us / 1000000)) $((us % 1000000 / 100000))
}

# phase NAME COMMAND...: runs a phase, records its time and whether it failed; returns the command's status.
phase() {
  local name="$1"
  shift
  echo
  echo "== ${name}: $*"
  local start=${EPOCHREALTIME/[.,]/} status=0
  "$@" || status=$?
  local end=${EPOCHREALTIME/[.,]/}
  local result="ok"
  if ((status != 0)); then
    result="FAILED (exit ${status})"
    failed_phases+=("${name}")
  fi
  timings+=("$(printf '%-13s %7s s  %s' "${name}" "$(elapsed_s "${start}" "${end}")" "${result}")")
  echo "== ${name}: ${result} in $(elapsed_s "${start}" "${end}") s"
  return "${status}"
}

# shellcheck disable=SC2317 # called through phase
run_ctest() {
  ctest --test-dir "${build_dir}" --output-on-failure --no-tests=error -j2 2>&1 | tee "${ctest_log}"
  return "${PIPESTATUS[0]}"
}

cd "${repo_root}"
ctest_log="$(mktemp)"
trap 'rm -f "${ctest_log}"' EXIT

if ! phase setup bash "${scripts}/setup.sh"; then
  failed=$((failed + 1))
  finish
fi
if ! phase check-format bash "${scripts}/check-format.sh"; then
  failed=$((failed + 1))
fi
if ! phase build bash "${scripts}/build.sh" "${build_dir}"; then
  failed=$((failed + 1))
  finish
fi
# clang-tidy over src/ (the product); CANYON_TIDY_TESTS=1 adds tests/ (8 more minutes on 2 cores).
tidy_scope=src
if [[ "${CANYON_TIDY_TESTS:-0}" == 1 ]]; then tidy_scope=all; fi
if ! phase check-tidy bash "${scripts}/check-tidy.sh" "${build_dir}" "${tidy_scope}"; then
  failed=$((failed + 1))
fi

ctest_status=0
phase ctest run_ctest || ctest_status=$?
# "100% tests passed, 0 tests failed out of 25"
summary="$(grep -E '[0-9]+% tests passed, [0-9]+ tests? failed out of [0-9]+' "${ctest_log}" | tail -1 || true)"
if [[ "${summary}" =~ ([0-9]+)\ tests?\ failed\ out\ of\ ([0-9]+) ]]; then
  failed=$((failed + BASH_REMATCH[1]))
  passed=$((passed + BASH_REMATCH[2] - BASH_REMATCH[1]))
elif ((ctest_status != 0)); then
  failed=$((failed + 1)) # ctest itself failed before running tests
fi
finish
