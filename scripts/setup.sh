#!/usr/bin/env bash
# Install every build and test dependency of canyon on Debian 12 (bookworm) with apt-get.
# Does nothing (no network, well under a second) when all packages are already installed.
# Runs as root, or through sudo when started by another user.
set -euo pipefail

packages=(
  build-essential cmake ninja-build git pkg-config
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools
  libeigen3-dev libceres-dev libspdlog-dev libyaml-cpp-dev libcli11-dev zlib1g-dev libzstd-dev
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  clang-format clang-tidy clang-14 libclang-rt-14-dev
  rtklib
  libxml2-utils
  libreaderwriterqueue-dev
  # deployment (issue 8): link emulator, namespaces, DDS-Security test PKI, dashboard server and its browser test
  libnetfilter-queue-dev iptables iproute2 iputils-ping openssl python3
  libcpp-httplib-dev nlohmann-json3-dev chromium python3-websocket nodejs
  # map tracks (issue 29): independent GPX and KML readers for the tracks' test
  python3-gpxpy python3-fastkml
)

# One dpkg-query call for all packages; a package dpkg has never heard of prints nothing and counts as missing.
installed="$(dpkg-query -W -f='${Package} ${db:Status-Status}\n' "${packages[@]}" 2> /dev/null || true)"
missing=()
for pkg in "${packages[@]}"; do
  if ! grep -qx "${pkg} installed" <<< "${installed}"; then
    missing+=("${pkg}")
  fi
done
# fastddsgen is a Java program: apt pulls in a runtime with it, but make sure `java` is there in any case.
if ! command -v java > /dev/null 2>&1; then
  missing+=(default-jre-headless)
fi

# The dashboard page is bundled with npm: Debian's npm package, unless a node installation brings its own npm.
if ! command -v npm > /dev/null 2>&1; then
  missing+=(npm)
fi

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages already installed, nothing to do"
  exit 0
fi

echo "setup: missing packages: ${missing[*]}"
if ((EUID == 0)); then
  as_root=()
elif command -v sudo > /dev/null 2>&1; then
  # Never wait for a password prompt without a terminal (CI, no stdin): fail instead.
  if [[ -t 0 ]]; then as_root=(sudo); else as_root=(sudo -n); fi
else
  echo "setup: error: installing packages needs root; run this script as root or install sudo" >&2
  exit 1
fi

export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
echo "setup: installed ${missing[*]}"
