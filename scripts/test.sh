#!/usr/bin/env bash
# The one command that sets up and runs canyon's whole test suite from a fresh clone:
#   setup (packages) -> check-format (cheap gate) -> build -> check-tidy -> ctest
# Works from any directory, without a terminal (CI=true, no stdin). Prints each phase's time, each skipped test with
# its reason and, last, the line
#   N passed, N failed, N skipped
# counted from ctest, where a failed gate (setup, format, build, tidy) counts as one more failure. Skipped tests are
# those ctest reports as skipped: a script test's exit 77 (SKIP_RETURN_CODE) and GoogleTest's GTEST_SKIP() (CMake's
# gtest_discover_tests sets SKIP_REGULAR_EXPRESSION "[  SKIPPED ]" on every test it adds). The reason is the skip
# message (GoogleTest: the GTEST_SKIP() text and its file:line; scripts: their "SKIP: ..." line, else their last line).
# In CI (CI=true or CI=1, and ../shared beside the repository) the datasets and the tools are there, so nothing may
# skip: every skipped test counts as a failure, named on a line of its own. Exits non-zero on any failure. Setup and
# build failures stop the run (nothing left to test); format and tidy failures do not, so one run reports everything.
# Usage: scripts/test.sh [BUILD_DIR]      (default: <repo>/build)
# Environment: CANYON_TIDY_TESTS=1 runs clang-tidy over tests/ too (default: src/ only, to keep CI under 30 minutes);
#   CANYON_TIDY_FULL=1 runs it over every file (default: the files that can differ from .ci/tidy-clean's commit).
#   CANYON_CTEST_ARGS: extra ctest arguments, split on spaces, e.g. "-R LiveRtcm" to run a subset (default: none).
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$(realpath -m "${1:-${repo_root}/build}")" # absolute: the phases run from the repository root
scripts="${repo_root}/scripts"

passed=0
failed=0
skipped=0
skip_lines=() # "NAME: REASON" of each skipped test
ci_skip_lines=() # the same in CI, where they count as failures
failed_phases=()
timings=()
run_start=${EPOCHREALTIME/[.,]/}

finish() {
  local end=${EPOCHREALTIME/[.,]/}
  echo
  echo "== summary"
  printf '  %s\n' "${timings[@]}"
  printf '  total: %s s\n' "$(elapsed_s "${run_start}" "${end}")"
  if ((${#skip_lines[@]} > 0)); then
    echo "  skipped (${#skip_lines[@]}):"
    printf '    %s\n' "${skip_lines[@]}"
  fi
  if ((${#ci_skip_lines[@]} > 0)); then
    echo "  FAILED: ${#ci_skip_lines[@]} skipped tests count as failures in CI (CI=${CI:-}, ${repo_root}/../shared present):"
    printf '    skipped in CI: %s\n' "${ci_skip_lines[@]}"
  fi
  if ((${#failed_phases[@]} > 0)); then
    echo "  failed: ${failed_phases[*]}"
  fi
  echo "${passed} passed, ${failed} failed, ${skipped} skipped"
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
  local extra=()
  if [[ -n "${CANYON_CTEST_ARGS:-}" ]]; then read -r -a extra <<< "${CANYON_CTEST_ARGS}"; fi
  ctest --test-dir "${build_dir}" --output-on-failure --no-tests=error -j2 --output-junit "${junit}" "${extra[@]}" 2>&1 |
    tee "${ctest_log}"
  return "${PIPESTATUS[0]}"
}

# skip_reasons JUNIT_XML: one line "NAME<TAB>REASON" per test ctest did not run (skipped or disabled), from its output.
skip_reasons() {
  python3 - "$1" "${repo_root}" << 'PY'
import os, re, sys
import xml.etree.ElementTree as ET

def reason(text, repo):
    lines = text.splitlines()
    for i, line in enumerate(lines):
        m = re.match(r"(.*):(\d+): Skipped$", line)  # GoogleTest: "FILE:LINE: Skipped", the message, "[  SKIPPED ]"
        if m:
            message = []
            for follow in lines[i + 1:]:
                if follow.startswith("[  SKIPPED ]"):
                    break
                if follow.strip():
                    message.append(follow.strip())
            where = m.group(1)
            if where.startswith(repo + os.sep):
                where = os.path.relpath(where, repo)
            return "%s (%s:%s)" % (" ".join(message) or "no reason given", where, m.group(2))
    for line in lines:
        if line.startswith("SKIP:"):
            return line[len("SKIP:"):].strip()
    rest = [line.strip() for line in lines if line.strip()]
    return rest[-1] if rest else "no reason given (no output)"

try:
    root = ET.parse(sys.argv[1]).getroot()
except (OSError, ET.ParseError) as e:
    sys.exit("no JUnit report: %s" % e)
for case in root.iter("testcase"):
    status = case.get("status")
    if status == "disabled":
        print("%s\tdisabled (DISABLED test property)" % case.get("name"))
    elif status == "notrun":
        out = case.find("system-out")
        text = out.text if out is not None and out.text else ""
        print("%s\t%s" % (case.get("name"), " ".join(reason(text, sys.argv[2]).split())))
PY
}

# in_ci: CI=true (or 1) with ../shared beside the repository: the datasets and tools are there, nothing may skip.
in_ci() {
  [[ "${CI:-}" == true || "${CI:-}" == 1 ]] && [[ -d "${repo_root}/../shared" ]]
}

cd "${repo_root}"
ctest_log="$(mktemp)"
junit="$(mktemp --suffix .xml)"
trap 'rm -f "${ctest_log}" "${junit}"' EXIT

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
# clang-tidy over src/ (the product); CANYON_TIDY_TESTS=1 adds tests/ (8 more minutes on 2 cores). Only the files
# whose result can differ from .ci/tidy-clean's commit, where a full run passed (a full run takes 17 minutes on 2
# cores); CANYON_TIDY_FULL=1 checks every file.
tidy_args=("${build_dir}" src)
if [[ "${CANYON_TIDY_TESTS:-0}" == 1 ]]; then
  tidy_args=("${build_dir}" all) # the recorded commit vouches for src/ only
elif [[ "${CANYON_TIDY_FULL:-0}" != 1 && -f "${repo_root}/.ci/tidy-clean" ]]; then
  tidy_args+=(--since-record "${repo_root}/.ci/tidy-clean")
fi
if ! phase check-tidy bash "${scripts}/check-tidy.sh" "${tidy_args[@]}"; then
  failed=$((failed + 1))
fi

ctest_status=0
phase ctest run_ctest || ctest_status=$?
# "100% tests passed, 0 tests failed out of 25": ctest counts a skipped test as passed, a test that could not start
# ("Not Run") as failed; disabled tests are outside the total. The skipped and disabled tests are listed under "The
# following tests did not run:" as "	 12 - NAME (Skipped)" / "(Disabled)".
summary="$(grep -E '[0-9]+% tests passed, [0-9]+ tests? failed out of [0-9]+' "${ctest_log}" | tail -1 || true)"
mapfile -t not_run < <(sed -nE 's/^[[:space:]]+[0-9]+ - (.+) \((Skipped|Disabled)\)$/\2 \1/p' "${ctest_log}")
if [[ "${summary}" =~ ([0-9]+)\ tests?\ failed\ out\ of\ ([0-9]+) ]]; then
  ctest_failed=${BASH_REMATCH[1]}
  ctest_total=${BASH_REMATCH[2]}
  ctest_skipped=0
  declare -A reasons=()
  if ((${#not_run[@]} > 0)); then
    while IFS=$'\t' read -r name why; do reasons["${name}"]="${why}"; done < <(skip_reasons "${junit}" || true)
  fi
  for entry in "${not_run[@]}"; do
    kind="${entry%% *}"
    name="${entry#* }"
    if [[ "${kind}" == Skipped ]]; then ctest_skipped=$((ctest_skipped + 1)); fi
    line="${name}: ${reasons[${name}]:-reason not found (see ${build_dir}/Testing/Temporary/LastTest.log)}"
    if in_ci; then ci_skip_lines+=("${line}"); else skip_lines+=("${line}"); fi
  done
  passed=$((passed + ctest_total - ctest_failed - ctest_skipped))
  failed=$((failed + ctest_failed))
  disabled=$((${#not_run[@]} - ctest_skipped))
  if in_ci; then
    failed=$((failed + ${#not_run[@]}))
    if ((${#not_run[@]} > 0)); then failed_phases+=("skipped-in-CI"); fi
  else
    skipped=$((skipped + ${#not_run[@]}))
  fi
  if ((disabled > 0)); then echo "note: ${disabled} disabled tests (outside ctest's total) counted as skipped"; fi
elif ((ctest_status != 0)); then
  failed=$((failed + 1)) # ctest itself failed before running tests
fi
finish
