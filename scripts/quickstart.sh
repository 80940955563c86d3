#!/usr/bin/env bash
# Sets canyon up on a fresh Debian 12 machine (packages, build) and runs its main job on the built-in default, with
# no external data: `canyon demo` generates the downtown street-canyon scenario (10 minutes, pedestrian, 20 km base),
# processes it with canyon's SPP, RTK and fusion modes and with RTKLIB's rnx2rtkp, scores all four against the
# scenario's exact truth (fix rate and correct-fix rate), prints the side-by-side table and writes the plots into
# out/demo/.
# Usage: scripts/quickstart.sh [BUILD_DIR] [canyon demo options...]     (default: <repo>/build)
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$(realpath -m "${1:-${repo_root}/build}")"
shift || true

echo "== setup: Debian packages"
bash "${repo_root}/scripts/setup.sh"
echo "== build: ${build_dir}"
bash "${repo_root}/scripts/build.sh" "${build_dir}"

echo "== canyon demo --out out/demo $*"
cd "${repo_root}"
"${build_dir}/canyon" demo --out out/demo "$@"
