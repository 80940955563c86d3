#!/usr/bin/env bash
# Configure (Release; Ninja when installed, else Make) and build canyon with all cores.
# Usage: scripts/build.sh [BUILD_DIR] [extra cmake -D options...]
# Idempotent and incremental: an existing build directory is reconfigured only when CMake decides it must be.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${1:-${repo_root}/build}"
shift || true
build_type="${CMAKE_BUILD_TYPE:-Release}"

configure_args=(-S "${repo_root}" -B "${build_dir}" -DCMAKE_BUILD_TYPE="${build_type}" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON)
if [[ ! -f "${build_dir}/CMakeCache.txt" ]]; then
  # Pick the generator only on first configure: CMake refuses to switch generators in an existing build dir.
  if command -v ninja > /dev/null 2>&1; then
    configure_args+=(-G Ninja)
  else
    configure_args+=(-G "Unix Makefiles")
  fi
fi

cmake "${configure_args[@]}" "$@"
cmake --build "${build_dir}" --parallel "$(nproc)"
