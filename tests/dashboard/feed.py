#!/usr/bin/env python3
"""Synthetic monitor snapshots (the schema of include/canyon/dashboard/dashboard.hpp) for the dashboard's browser
test: six stages, a rover walking a 40 m loop with fixed, float and VIO fill-in stretches, a base correction every
second, link losses, an alignment converging. One JSON object per line at --rate Hz for --seconds.
  feed.py [--rate HZ] [--seconds S] [--bad-lines]   (--bad-lines mixes in lines the dashboard must skip)
"""
import argparse
import json
import math
import random
import sys
import time

STAGES = ["ingest", "time_bridge", "alignment", "prediction", "update", "ambiguity"]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--rate", type=float, default=5.0)
    p.add_argument("--seconds", type=float, default=60.0)
    p.add_argument("--bad-lines", action="store_true")
    a = p.parse_args()
    rng = random.Random(1)
    n = int(a.rate * a.seconds)
    lost = packets = 0
    for i in range(n):
        t = i / a.rate
        phase = (t % 30.0)
        status = 1 if phase < 18 else (2 if phase < 24 else 7)
        angle = t / 40.0 * 2 * math.pi
        stages = {}
        e2e_p50 = 0.0
        for k, name in enumerate(STAGES):
            base = (10 + 15 * k) * (1 + 0.3 * rng.random())
            stages[name] = {"p50_us": round(base, 1), "p95_us": round(base * 2.1, 1), "p99_us": round(base * 3.5, 1),
                            "max_us": round(base * 6, 1), "count": i + 1}
            e2e_p50 += base
        packets += 12
        lost += 1 if rng.random() < 0.15 else 0
        snap = {
            "t_s": round(t, 3),
            "stages": stages,
            "end_to_end": {"p50_us": round(e2e_p50, 1), "p95_us": round(e2e_p50 * 2, 1),
                           "p99_us": round(e2e_p50 * 3, 1), "max_us": round(e2e_p50 * 5, 1), "count": i + 1},
            "correction_age_s": round(0.02 + (t % 1.0), 3),
            "queues": {"ingest": rng.randint(0, 2), "update": rng.randint(0, 1)},
            "drops": {"vio_decimated": i // 50, "link_lost": lost, "link_packets": packets},
            "solution": {"seq": i, "status": status, "lat_deg": 48.137 + 20 * math.sin(angle) / 6371000 * 180 / math.pi,
                         "lon_deg": 11.575 + 20 * math.cos(angle) / (6371000 * math.cos(math.radians(48.137))) * 180 / math.pi,
                         "height_m": 520.0 + 0.05 * math.sin(t), "n_sats": 14 + int(4 * math.sin(t / 7)),
                         "pruned": ["G05", "E11"][: int(phase // 10)], "ratio": round(3 + 5 * (status == 1), 2),
                         "hpl_m": round(0.06 if status == 1 else 1.8, 3), "vpl_m": round(0.12 if status == 1 else 3.0, 3)},
            "alignment": {"rmse_m": round(0.3 * math.exp(-t / 20) + 0.03, 4), "eigen_ratio": round(2 + 10 * (1 - math.exp(-t / 15)), 3),
                          "lever_arm_m": [round(-0.1 + 0.05 * math.exp(-t / 10), 4), round(0.05 - 0.03 * math.exp(-t / 10), 4), 0.0]},
        }
        print(json.dumps(snap), flush=True)
        if a.bad_lines and i % 25 == 7:
            print("{this is not a snapshot", flush=True)
        time.sleep(1.0 / a.rate)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except BrokenPipeError:
        sys.exit(0)
