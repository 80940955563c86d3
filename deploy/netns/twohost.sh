#!/usr/bin/env bash
# The two-host setup on one machine: network namespaces cy-base (10.77.0.1/24) and cy-rover (10.77.0.2/24) joined by
# a veth pair (cyb0 <-> cyr0), only their own addresses (and lo), and the 20 km WAN emulated in user space: in each
# namespace an iptables rule sends every IPv4 packet leaving the veth to NFQUEUE 0, where canyon-linkemu delays,
# drops, duplicates, reorders or corrupts it (this kernel has no netem qdisc).
#
#   twohost.sh up [key=value ...]    create (replacing a previous setup) with the link options (default: the 20 km
#                                    link, delay_ms=20 jitter_ms=5 loss=0.01, in each direction)
#   twohost.sh set key=value ...     change link options live (both directions; SIGHUP to the emulators)
#   twohost.sh stats                 the emulators' counters (JSON, one line per direction)
#   twohost.sh down                  stop the emulators and remove the namespaces
#   twohost.sh check                 exit 0 when root, `ip netns` and canyon-linkemu are usable, else 77 and why
# Link option keys: include/canyon/netemu/link_model.hpp (delay_ms jitter_ms loss rate_kbps queue_limit_ms duplicate
# reorder reorder_ms corrupt outage seed). Run a program on a host: `ip netns exec cy-base CMD`.
# Environment: CANYON_BUILD_DIR (default <repo>/build), CANYON_NETNS_STATE (default /run/canyon-netns).
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build_dir="${CANYON_BUILD_DIR:-${repo_root}/build}"
linkemu="${build_dir}/canyon-linkemu"
state="${CANYON_NETNS_STATE:-/run/canyon-netns}"
base_ns=cy-base
rover_ns=cy-rover
base_addr=10.77.0.1
rover_addr=10.77.0.2
default_link=(delay_ms=20 jitter_ms=5 loss=0.01)

die() {
  echo "twohost: error: $*" >&2
  exit 1
}

check() {
  if ((EUID != 0)); then
    echo "twohost: needs root (network namespaces, iptables, NFQUEUE)"
    return 77
  fi
  if ! ip netns list > /dev/null 2>&1; then
    echo "twohost: 'ip netns' does not work here"
    return 77
  fi
  if ! command -v iptables > /dev/null 2>&1; then
    echo "twohost: iptables not installed (scripts/setup.sh installs it)"
    return 77
  fi
  if [[ ! -x "${linkemu}" ]]; then
    echo "twohost: ${linkemu} not built (needs libnetfilter-queue-dev; cmake --build BUILD --target canyon-linkemu)"
    return 77
  fi
  return 0
}

write_link_conf() {
  local file="$1"
  shift
  local tmp="${file}.tmp"
  : > "${tmp}"
  local kv
  for kv in "$@"; do
    [[ "${kv}" == *=* ]] || die "link option '${kv}' is not key=value"
    echo "${kv}" >> "${tmp}"
  done
  mv "${tmp}" "${file}"
}

down() {
  local ns pidfile
  for ns in "${base_ns}" "${rover_ns}"; do
    pidfile="${state}/linkemu-${ns}.pid"
    if [[ -f "${pidfile}" ]]; then
      local pid
      pid="$(cat "${pidfile}")"
      if kill -0 "${pid}" 2> /dev/null; then
        kill -TERM "${pid}" 2> /dev/null || true
        for _ in $(seq 50); do
          kill -0 "${pid}" 2> /dev/null || break
          sleep 0.1
        done
        kill -KILL "${pid}" 2> /dev/null || true
      fi
      rm -f "${pidfile}"
    fi
    # Processes still running in the namespace (started by tests) would keep it alive: stop them.
    if ip netns list | grep -qw "${ns}"; then
      local pids
      pids="$(ip netns pids "${ns}" 2> /dev/null || true)"
      if [[ -n "${pids}" ]]; then
        # shellcheck disable=SC2086 # a list of pids
        kill -TERM ${pids} 2> /dev/null || true
        sleep 0.5
        # shellcheck disable=SC2086
        kill -KILL ${pids} 2> /dev/null || true
      fi
      ip netns del "${ns}"
    fi
  done
  rm -rf "${state}"
}

up() {
  check || exit $?
  down
  mkdir -p "${state}"
  local link=("${default_link[@]}")
  if (($# > 0)); then link=("$@"); fi
  write_link_conf "${state}/link.conf" "${link[@]}"

  ip netns add "${base_ns}"
  ip netns add "${rover_ns}"
  ip link add cyb0 netns "${base_ns}" type veth peer name cyr0 netns "${rover_ns}"
  ip -n "${base_ns}" addr add "${base_addr}/24" dev cyb0
  ip -n "${rover_ns}" addr add "${rover_addr}/24" dev cyr0
  local ns dev
  for ns in "${base_ns}" "${rover_ns}"; do
    dev=cyb0
    [[ "${ns}" == "${rover_ns}" ]] && dev=cyr0
    ip -n "${ns}" link set lo up
    ip -n "${ns}" link set "${dev}" up
    # Multicast discovery (LAN profile) leaves through the veth.
    ip -n "${ns}" route add 224.0.0.0/4 dev "${dev}"
    # Every IPv4 packet leaving the veth goes through the emulator, except its own duplicates (mark 0x77). Without
    # --queue-bypass: when the emulator is not running the link is down, as it should be for a dead link.
    ip netns exec "${ns}" iptables -A OUTPUT -o "${dev}" -m mark ! --mark 0x77 -j NFQUEUE --queue-num 0
    ip netns exec "${ns}" "${linkemu}" --queue 0 --config "${state}/link.conf" \
      --stats "${state}/stats-${ns}.json" > "${state}/linkemu-${ns}.log" 2>&1 &
    echo $! > "${state}/linkemu-${ns}.pid"
  done
  # The emulators are up once they wrote their first counters.
  for _ in $(seq 50); do
    if [[ -f "${state}/stats-${base_ns}.json" && -f "${state}/stats-${rover_ns}.json" ]]; then break; fi
    sleep 0.1
  done
  for ns in "${base_ns}" "${rover_ns}"; do
    if ! kill -0 "$(cat "${state}/linkemu-${ns}.pid")" 2> /dev/null; then
      cat "${state}/linkemu-${ns}.log" >&2
      down
      die "canyon-linkemu did not start in ${ns}"
    fi
  done
  echo "twohost: ${base_ns} ${base_addr} <-> ${rover_ns} ${rover_addr}, link: ${link[*]}"
}

set_link() {
  [[ -f "${state}/link.conf" ]] || die "not up (run: $0 up)"
  (($# > 0)) || die "usage: $0 set key=value ..."
  # Keys given replace the same keys of the current file; the others stay.
  local current=() kv key
  mapfile -t current < "${state}/link.conf"
  for kv in "$@"; do
    [[ "${kv}" == *=* ]] || die "link option '${kv}' is not key=value"
    key="${kv%%=*}"
    local kept=()
    local line
    for line in "${current[@]}"; do
      [[ "${line%%=*}" == "${key}" ]] || kept+=("${line}")
    done
    current=("${kept[@]}" "${kv}")
  done
  write_link_conf "${state}/link.conf" "${current[@]}"
  local ns
  for ns in "${base_ns}" "${rover_ns}"; do
    kill -HUP "$(cat "${state}/linkemu-${ns}.pid")"
  done
  echo "twohost: link: ${current[*]}"
}

stats() {
  local ns
  for ns in "${base_ns}" "${rover_ns}"; do
    printf '%s ' "${ns}"
    cat "${state}/stats-${ns}.json" 2> /dev/null || echo "{}"
  done
}

cmd="${1:-}"
shift || true
case "${cmd}" in
  up) up "$@" ;;
  down) down ;;
  set) set_link "$@" ;;
  stats) stats ;;
  check) check ;;
  *)
    echo "usage: $0 up [key=value ...] | set key=value ... | stats | down | check" >&2
    exit 2
    ;;
esac
