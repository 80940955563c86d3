#!/usr/bin/env python3
"""One-way UDP probe across the two-host namespaces: measures what the emulated link really does.

  udp_probe.py recv --port P --count N [--timeout S]     prints one JSON object with the figures
  udp_probe.py send --to ADDR --port P --count N --rate HZ [--size BYTES]

Each datagram carries its sequence number, the sender's CLOCK_MONOTONIC time (network namespaces share the clock,
so the one-way delay is measured directly) and a CRC-32 of the rest, so the receiver counts lost, duplicated,
reordered and corrupted datagrams (the emulator clears the UDP checksum of the packets it corrupts).
"""
import argparse
import json
import socket
import struct
import sys
import time
import zlib

HEADER = struct.Struct("!QqI")  # seq, send monotonic ns, crc32 of seq, time and padding


def percentile(sorted_values, p):
    if not sorted_values:
        return None
    k = min(len(sorted_values) - 1, max(0, round(p / 100.0 * (len(sorted_values) - 1))))
    return sorted_values[k]


def recv(args):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
    sock.bind(("0.0.0.0", args.port))
    sock.settimeout(args.timeout)
    seen = set()
    delays_ms = []
    duplicates = reordered = corrupted = 0
    highest = -1
    while True:
        try:
            data = sock.recv(65536)
        except socket.timeout:
            break
        now = time.monotonic_ns()
        if len(data) < HEADER.size:
            corrupted += 1
            continue
        seq, sent_ns, crc = HEADER.unpack_from(data)
        if zlib.crc32(data[:HEADER.size - 4] + data[HEADER.size:]) != crc or seq >= args.count:
            corrupted += 1
            continue
        if seq in seen:
            duplicates += 1
            continue
        seen.add(seq)
        if seq < highest:
            reordered += 1
        highest = max(highest, seq)
        delays_ms.append((now - sent_ns) / 1e6)
        if seq == args.count - 1 and len(seen) == args.count:
            break
    delays_ms.sort()
    result = {
        "sent": args.count,
        "received": len(seen),
        "lost": args.count - len(seen),
        "loss_pct": round(100.0 * (args.count - len(seen)) / args.count, 3),
        "duplicates": duplicates,
        "reordered": reordered,
        "corrupted": corrupted,
        "delay_ms": {
            "min": round(delays_ms[0], 3) if delays_ms else None,
            "p50": round(percentile(delays_ms, 50), 3) if delays_ms else None,
            "mean": round(sum(delays_ms) / len(delays_ms), 3) if delays_ms else None,
            "p95": round(percentile(delays_ms, 95), 3) if delays_ms else None,
            "max": round(delays_ms[-1], 3) if delays_ms else None,
        },
    }
    print(json.dumps(result))
    return 0


def send(args):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    padding = bytes((i * 7) & 0xFF for i in range(max(0, args.size - HEADER.size)))
    period = 1.0 / args.rate
    start = time.monotonic()
    for seq in range(args.count):
        target = start + seq * period
        delay = target - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        head = struct.pack("!Qq", seq, time.monotonic_ns())
        sock.sendto(head + struct.pack("!I", zlib.crc32(head + padding)) + padding, (args.to, args.port))
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="mode", required=True)
    r = sub.add_parser("recv")
    r.add_argument("--port", type=int, required=True)
    r.add_argument("--count", type=int, required=True)
    r.add_argument("--timeout", type=float, default=3.0, help="stop after this many seconds without a datagram")
    s = sub.add_parser("send")
    s.add_argument("--to", required=True)
    s.add_argument("--port", type=int, required=True)
    s.add_argument("--count", type=int, required=True)
    s.add_argument("--rate", type=float, default=100.0)
    s.add_argument("--size", type=int, default=200)
    args = parser.parse_args()
    if args.count <= 0:
        parser.error("--count must be > 0")
    return recv(args) if args.mode == "recv" else send(args)


if __name__ == "__main__":
    sys.exit(main())
