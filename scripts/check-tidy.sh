#!/usr/bin/env bash
# Run clang-tidy 14 with the repository's .clang-tidy over the project's own .cpp files (tracked files under src/
# and tests/, never generated code) using BUILD_DIR/compile_commands.json, two files at a time. Fails on any
# diagnostic.
# Usage: scripts/check-tidy.sh BUILD_DIR [all|src] [--since-record FILE] [--record FILE]
#   all (default): src/ and tests/; src: the product's sources only (scripts/test.sh's default: tidy over the test
#   files, which expand GoogleTest and Eigen, takes another 8 minutes on 2 cores and would push CI past 30 minutes).
#   --since-record FILE: check only the files whose tidy result can differ from that of the commit FILE names (its
#     first line), where a full run passed: a .cpp is checked when it or any header it includes (the build's own
#     dependency list, `ninja -t deps`) differs from that commit in the working tree, or when its compile command
#     differs from the one FILE holds for it (flags, defines, include paths). Everything is checked when the commit
#     is unknown, the build is not a Ninja build, or .clang-tidy or idl/ (generated headers) changed. clang-tidy reads
#     nothing else (this script only picks the files), so the answer equals a full run's.
#   --record FILE: after a full run that passes on a clean working tree, write HEAD and each file's compile command
#     (a hash) to FILE; scripts/test.sh uses .ci/tidy-clean (for src/ only).
set -euo pipefail

usage() {
  echo "usage: $0 BUILD_DIR [all|src] [--since-record FILE] [--record FILE]" >&2
  exit 2
}
(($# >= 1)) || usage
build_arg="$1"
shift
scope=all
since=""
record=""
while (($# > 0)); do
  case "$1" in
    all | src) scope="$1" ;;
    --since-record)
      (($# >= 2)) || usage
      since="$(realpath -m "$2")"
      shift
      ;;
    --record)
      (($# >= 2)) || usage
      record="$(realpath -m "$2")"
      shift
      ;;
    *) usage ;;
  esac
  shift
done
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [[ ! -d "${build_arg}" ]]; then
  echo "check-tidy: error: build directory ${build_arg} does not exist; build first (scripts/build.sh)" >&2
  exit 1
fi
build_dir="$(cd "${build_arg}" && pwd)"
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

# changed_files RECORD FILE...: the FILEs whose tidy result can differ from the RECORD's commit's, one per line; or,
# when every file must be checked, the line "full: REASON" followed by all FILEs.
changed_files() {
  local record_file="$1"
  shift
  local commit reason=""
  commit="$(head -n 1 "${record_file}" 2> /dev/null || true)"
  local changed=()
  if [[ -z "${commit}" ]] || ! git -C "${repo_root}" cat-file -e "${commit}^{commit}" 2> /dev/null; then
    reason="commit '${commit}' of ${record_file} is not in this clone"
  elif [[ ! -f "${build_dir}/build.ninja" ]]; then
    reason="not a Ninja build: no dependency list"
  else
    mapfile -t changed < <(git -C "${repo_root}" diff --name-only "${commit}" -- &&
      git -C "${repo_root}" ls-files --others --exclude-standard)
    local path
    for path in "${changed[@]}"; do
      if [[ "${path}" == .clang-tidy || "${path}" == idl/* ]]; then
        reason="${path} changed since ${commit}"
        break
      fi
    done
  fi
  if [[ -n "${reason}" ]]; then
    echo "full: ${reason}"
    printf '%s\n' "$@"
    return
  fi
  # ninja -t deps: "OBJECT: #deps N ..." then one indented dependency per line, the source first.
  (cd "${build_dir}" && ninja -t deps) | python3 "${repo_root}/scripts/tidy_changed.py" "${repo_root}" "${build_dir}" \
    "${record_file}" "$(printf '%s\n' "${changed[@]}")" "$@"
}

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
full=1
if [[ -n "${since}" ]]; then
  mapfile -t files < <(changed_files "${since}" "${files[@]}")
  if [[ "${files[0]:-}" == full:* ]]; then
    echo "check-tidy: checking every file (${files[0]#full: })"
    files=("${files[@]:1}")
  else
    full=0
    echo "check-tidy: ${#files[@]} files can differ from $(head -n 1 "${since}"), where every file passed (${since})"
  fi
fi
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
if [[ -n "${record}" ]]; then
  if ((full == 0)) || [[ -n "$(git status --porcelain)" ]]; then
    echo "check-tidy: not recorded: --record needs a full run on a clean working tree" >&2
    exit 1
  fi
  python3 "${repo_root}/scripts/tidy_changed.py" --record "${repo_root}" "${build_dir}" "$(git rev-parse HEAD)" \
    "${files[@]}" > "${record}"
  echo "check-tidy: recorded $(head -n 1 "${record}") and ${#files[@]} compile commands in ${record} (commit it)"
fi
