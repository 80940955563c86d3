#!/usr/bin/env bash
# Fail when a tracked C++ file under include/, src/ or tests/ differs from clang-format's output (.clang-format).
# Usage: scripts/check-format.sh [--fix]    --fix rewrites the files in place instead.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
fix=0
case "${1:-}" in
  "") ;;
  --fix) fix=1 ;;
  *)
    echo "usage: $0 [--fix]" >&2
    exit 2
    ;;
esac

# The style is pinned to clang-format 14 (Debian 12): other versions format some constructs differently.
clang_format="$(command -v clang-format-14 || command -v clang-format || true)"
if [[ -z "${clang_format}" ]]; then
  echo "check-format: error: clang-format not found (scripts/setup.sh installs it)" >&2
  exit 1
fi

cd "${repo_root}"
mapfile -t files < <(git ls-files -- 'include/*.hpp' 'include/*.cpp' 'src/*.hpp' 'src/*.cpp' 'tests/*.hpp' 'tests/*.cpp')
if ((${#files[@]} == 0)); then
  echo "check-format: no files to check"
  exit 0
fi

if ((fix)); then
  "${clang_format}" -i --style=file "${files[@]}"
  echo "check-format: formatted ${#files[@]} files"
  exit 0
fi

bad=()
for file in "${files[@]}"; do
  if ! "${clang_format}" --style=file "${file}" | cmp -s - "${file}"; then
    bad+=("${file}")
  fi
done
if ((${#bad[@]} > 0)); then
  echo "check-format: ${#bad[@]} of ${#files[@]} files differ from clang-format (fix with scripts/check-format.sh --fix):"
  printf '  %s\n' "${bad[@]}"
  exit 1
fi
echo "check-format: ${#files[@]} files OK"
