# shellcheck shell=bash
# The ROS 2 and MCAP test scripts' common start (sourced by wire_check.sh and replay_check.sh): the independent
# decoders (package-lock.json, npm ci, install scripts not run) into BUILD/NAME, never the source tree; a scratch
# folder `tmp` removed on exit with the background processes listed in `pids`; a DDS domain of the run's own.
# Usage: source common.sh BUILD NAME   (exits 77, SKIP:, without npm or the npm registry)

decoders=$1/$2
command -v npm > /dev/null || { echo "SKIP: npm not found (scripts/setup.sh installs it)"; exit 77; }
mkdir -p "$decoders"
cp "$here/package.json" "$here/package-lock.json" "$here"/*.mjs "$decoders/"
if [[ ! -f $decoders/node_modules/.package-lock.json || $here/package-lock.json -nt $decoders/node_modules/.package-lock.json ]]; then
  (cd "$decoders" && npm ci --no-audit --no-fund --ignore-scripts --loglevel=error) ||
    { echo "SKIP: npm ci failed for the independent decoders (is the npm registry reachable?)"; exit 77; }
fi

tmp=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2> /dev/null || true; done
  rm -rf "$tmp"
}
trap cleanup EXIT
domain=$((100 + RANDOM % 100))
