#!/usr/bin/env bash
# Run clang-tidy 14 with the repository's .clang-tidy over the project's own .cpp files (tracked files under src/
# and tests/, never generated code) using BUILD_DIR/compile_commands.json, two files at a time. Fails on any
# diagnostic.
# Usage: scripts/check-tidy.sh BUILD_DIR [all|src]
#   all (default): src/ and tests/; src: the product's sources only (scripts/test.sh's default: tidy over the test
#   files, which expand GoogleTest and Eigen, takes another 8 minutes on 2 cores and would push CI past 30 minutes).
set -euo pipefail

if (($# < 1 || $# > 2)) || [[ "${2:-all}" != all && "${2:-all}" != src ]]; then
  echo "usage: $0 BUILD_DIR [all|src]" >&2
  exit 2
fi
scope="${2:-all}"
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [[ ! -d "$1" ]]; then
  echo "check-tidy: error: build directory $1 does not exist; build first (scripts/build.sh)" >&2
  exit 1
fi
build_dir="$(cd "$1" && pwd)"
jobs="${CANYON_TIDY_JOBS:-2}"

if [[ ! -f "${build_dir}/compile_commands.json" ]]; then
  echo "check-tidy: error: ${build_dir}/compile_commands.json missing; configure first (scripts/build.sh)" >&2
  exit 1
fi
clang_tidy="$(command -v clang-tidy-14 || command -v clang-tidy || true)"
if [[ -z "${clang_tidy}" ]]; then
  echo "check-tidy: error: clang-tidy not found (scripts/setup.sh installs it)" >&2
  exit 1
fi

cd "${repo_root}"
# Tracked sources that the build compiles; a tracked file that no target builds yet is reported and skipped.
if [[ "${scope}" == src ]]; then
  mapfile -t tracked < <(git ls-files -- 'src/*.cpp')
else
  mapfile -t tracked < <(git ls-files -- 'src/*.cpp' 'tests/*.cpp')
fi
files=()
for file in "${tracked[@]}"; do
  if grep -qF "\"file\": \"${repo_root}/${file}\"" "${build_dir}/compile_commands.json"; then
    files+=("${repo_root}/${file}")
  else
    echo "check-tidy: skipping ${file}: not in the compilation database (no target builds it)"
  fi
done
if ((${#files[@]} == 0)); then
  echo "check-tidy: no files to check"
  exit 0
fi

log="$(mktemp)"
trap 'rm -f "${log}"' EXIT
status=0
if command -v run-clang-tidy-14 > /dev/null 2>&1; then
  # run-clang-tidy takes regular expressions: match exactly the listed files. It buffers each file's output.
  regex="^($(printf '%s\n' "${files[@]}" | sed 's/[][\.^$*+?(){}|]/\\&/g' | paste -sd '|'))\$"
  run-clang-tidy-14 -clang-tidy-binary "${clang_tidy}" -p "${build_dir}" -j "${jobs}" -quiet "${regex}" \
    > "${log}" 2>&1 || status=$?
else
  # Buffer each file's output so that two parallel runs do not interleave their diagnostics.
  # shellcheck disable=SC2016 # expanded by the inner shell
  printf '%s\0' "${files[@]}" | xargs -0 -n 1 -P "${jobs}" sh -c \
    'out="$("$0" -p "$1" --quiet "$2" 2>&1)"; rc=$?; printf "%s\n" "$out"; exit "$rc"' \
    "${clang_tidy}" "${build_dir}" > "${log}" 2>&1 || status=$?
fi

# Keep the diagnostics, drop colours (run-clang-tidy-14 always asks for them) and per-file noise.
sed -i 's/\x1b\[[0-9;]*m//g' "${log}"
grep -vE '^([0-9]+ warnings? (and [0-9]+ errors? )?generated\.|Suppressed [0-9]+ warnings|Use -header-filter|/[^ ]*clang-tidy[^ ]* |$)' \
  "${log}" || true
# .clang-tidy turns every warning into an error; fail on a stray "warning:" as well in case that changes.
if ((status != 0)) || grep -qE '(warning|error): ' "${log}"; then
  echo "check-tidy: FAILED (${#files[@]} files)"
  exit 1
fi
echo "check-tidy: ${#files[@]} files OK"
