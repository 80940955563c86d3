#!/usr/bin/env bash
# Sets canyon up on a fresh Debian 12 machine (packages, build) and runs its main job on the built-in default:
# single-point positioning of the real cssrlib-kinematic-doy265 drive (../shared/data beside the repository),
# written to out/spp-cssrlib-kinematic.pos in RTKLIB's .pos format.
# Usage: scripts/quickstart.sh [BUILD_DIR]      (default: <repo>/build)
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$(realpath -m "${1:-${repo_root}/build}")"
config="${repo_root}/config/spp-cssrlib-kinematic.yaml"
data="${repo_root}/../shared/data/cssrlib-kinematic-doy265"

echo "== setup: Debian packages"
bash "${repo_root}/scripts/setup.sh"
echo "== build: ${build_dir}"
bash "${repo_root}/scripts/build.sh" "${build_dir}"

if [[ ! -d "${data}" ]]; then
  echo "error: the default job reads the shared dataset ${data}, which is not present." >&2
  echo "       Put the shared/ folder beside this repository, or run your own data:" >&2
  echo "       ${build_dir}/canyon process --mode spp --rover ROVER.obs --nav NAV --out SOL.pos" >&2
  exit 1
fi

echo "== canyon process --config config/spp-cssrlib-kinematic.yaml"
cd "${repo_root}"
"${build_dir}/canyon" process --config "${config}"
out="${repo_root}/out/spp-cssrlib-kinematic.pos"
echo
echo "First solutions (GPST week, seconds, latitude, longitude, height, Q=5 single point, satellites, sigmas):"
grep -v '^%' "${out}" | head -n 5
echo "..."
echo "Solution file: ${out}"
