#!/usr/bin/env python3
"""canyon across the two-host namespaces (twohost.sh): canyon-base in cy-base, subscribers in cy-rover, over the
emulated 20 km link. Every scenario prints one JSON object per result and exits non-zero when an expectation fails.

  netns_suite.py relay [--subscribers N] [--secure] [--profile P] [--pace X] [--link k=v ...]
        one base run to N subscribers: every frame arrives, in order, no duplicate; latency percentiles
  netns_suite.py security
        intruders (no security; an identity of another CA; a valid identity without publish permission) reach no
        subscriber and read nothing; corrupted packets: the secure stream delivers no tampered frame
  netns_suite.py rover [--secure] [--pace X] [--seconds S] [--link k=v ...]
        canyon-base replays the instinct-spirent-rtk-sim base in real time (pace 1) in cy-base; canyon rover,
        canyon record (solutions, corrections) and canyon monitor --json in cy-rover: the recorded .pos must equal
        `canyon process` on the same rover file and the recorded corrections byte for byte, one solution per epoch;
        latency percentiles from the monitor (--seconds: only the rover file's first S seconds)
  netns_suite.py faults [--short] [--secure]
        the fault suite on base -> rover (instinct, real time) and a probe subscriber: 20 % loss, outage,
        duplicated/reordered/corrupted packets, the rover killed and restarted, the base killed and restarted; the
        probe's and the rover's recovery times, and ROVER_EXPECTATIONS checked (a broken one fails the run);
        --short is the CI variant (seconds instead of minutes)
  netns_suite.py live --json-lines FILE [--seconds S] [--secure]
        real dashboard data: canyon-base replays matrtklib-static in real time, a subscriber in cy-rover writes a
        snapshot per second (correction age, transport latency, link loss from the emulator's counters) to FILE;
        every 40 s the link has 20 % loss for 10 s and then a 10 s outage. Serve it with
        `canyon-dashboard --input FILE --follow`
  netns_suite.py short
        what ctest runs: relay (4 subscribers), security, rover (pace 4, 120 s of data), faults --short

Needs root, `ip netns`, iptables and BUILD/canyon-linkemu (exit 77 with the reason otherwise, which ctest shows as
skipped). Environment: CANYON_BUILD_DIR (default <repo>/build), CANYON_SHARED_DATA_DIR (default <repo>/../shared/data).
Setup.probe wraps the frame-counting subscriber; RoverHost runs the rover host's processes (rover, recorders,
monitor) and reads what they recorded.
"""
import argparse
import datetime
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BUILD = os.environ.get("CANYON_BUILD_DIR", os.path.join(REPO, "build"))
DATA = os.environ.get("CANYON_SHARED_DATA_DIR", os.path.join(REPO, "..", "shared", "data"))
TWOHOST = os.path.join(REPO, "deploy", "netns", "twohost.sh")
STATE = os.environ.get("CANYON_NETNS_STATE", "/run/canyon-netns")
LINK_20KM = ["delay_ms=20", "jitter_ms=5", "loss=0.01"]
DOMAIN = 42
SKIP = 77

# instinct-spirent-rtk-sim: a dynamic rover and a static base, 601 epochs at 1 Hz (the dataset of the rover loopback).
INSTINCT = "instinct-spirent-rtk-sim"
INSTINCT_ROVER = "iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs"
INSTINCT_BASE = "iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs"
INSTINCT_NAV = "RINEX_GN_Spirent.23N"
GPS_EPOCH = datetime.datetime(1980, 1, 6)
FIXED, FLOAT = 1, 2  # solution status (canyon::core::SolutionStatus, RTKLIB's Q)

# What the rover must show under each fault (checked by faults(): a broken one fails the run).
ROVER_EXPECTATIONS = {
    "every_epoch_one_solution": "solution sequence numbers contiguous from 0 in every rover run, one per GNSS epoch "
                                "(epoch times 1 s apart, none twice), through every fault",
    "never_stops": "the rover process is alive after every fault (until the suite stops it)",
    "refix_within_s": 10.0,  # status back to fixed within 10 s after the link is restored (or a process restarted)
    "stale_corrections_unused": "no fixed or float solution from corrections older than the rover's rtk.max_age_s",
    "max_rss_growth_mb": 8.0,  # rover VmRSS, each run: the last sample at most this much above the first fixed one
}

def log(msg):
    print(f"[netns_suite {time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, text=True, capture_output=True, **kw)


def twohost(*args):
    env = dict(os.environ, CANYON_BUILD_DIR=BUILD, CANYON_NETNS_STATE=STATE)
    return subprocess.run(["bash", TWOHOST, *args], check=True, text=True, capture_output=True, env=env).stdout


def link_stats():
    out = {}
    for ns in ("cy-base", "cy-rover"):
        try:
            with open(os.path.join(STATE, f"stats-{ns}.json")) as f:
                out[ns] = json.load(f)
        except (OSError, ValueError):
            out[ns] = {}
    return out


def check_environment():
    env = dict(os.environ, CANYON_BUILD_DIR=BUILD)
    r = subprocess.run(["bash", TWOHOST, "check"], text=True, capture_output=True, env=env)
    if r.returncode != 0:
        return r.stdout.strip() or r.stderr.strip()
    for exe in ("canyon", "canyon-base", "canyon-rtcm-probe", "canyon-rover", "canyon-record", "canyon-monitor"):
        if not os.access(os.path.join(BUILD, exe), os.X_OK):
            return f"{BUILD}/{exe} not built"
    needed = (("cssrlib-static-doy078", "3034078M1.21O"), (INSTINCT, INSTINCT_ROVER), (INSTINCT, INSTINCT_BASE))
    if not all(os.path.exists(os.path.join(DATA, *f)) for f in needed):
        return f"shared datasets not found at {DATA}"
    return None


class Setup:
    """Namespaces up for the duration of a `with` block, with the profiles of one deployment variant."""

    def __init__(self, tmp, profile="wan-initial-peers", secure=False, link=None):
        self.tmp = tmp
        self.profile = profile
        self.secure = secure
        self.link = link or LINK_20KM
        self.procs = []
        self.pki = os.path.join(tmp, "pki") if secure else None

    def __enter__(self):
        if self.secure and not os.path.exists(os.path.join(self.pki, "governance.p7s")):
            run(["bash", os.path.join(REPO, "deploy", "security", "make-pki.sh"), self.pki])
        twohost("up", *self.link)
        if self.profile == "wan-discovery-server":
            self.spawn("cy-base", ["fast-discovery-server", "-i", "0", "-l", "10.77.0.1", "-p", "11811"],
                       os.path.join(self.tmp, "discovery.log"))
            time.sleep(1.0)
        return self

    def __exit__(self, *exc):
        for p in self.procs:
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
        for p in self.procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
        twohost("down")

    def profiles(self, role):
        if self.secure:
            return os.path.join(self.pki, role, f"{self.profile}.xml")
        return os.path.join(REPO, "deploy", "dds", f"{self.profile}.xml")

    def spawn(self, ns, cmd, logfile, stdout=None):
        err = open(logfile, "w")
        p = subprocess.Popen(["ip", "netns", "exec", ns, *cmd], stdout=stdout or err, stderr=err, text=True)
        self.procs.append(p)
        return p

    def base(self, name, dataset="cssrlib-static-doy078", pace=5.0, wait_clients=1, topic="canyon/rtcm", obs=None):
        """canyon-base in cy-base replaying a dataset's base file (or `obs`, a slice of it) at `pace`."""
        files = {
            "cssrlib-static-doy078": ("3034078M1.21O", ["SEPT078M.21P"], 3034),
            "matrtklib-static": ("base.obs", ["base.nav"], 0),
            INSTINCT: (INSTINCT_BASE, [INSTINCT_NAV], 1),
        }[dataset]
        path, navs, station = files
        obs = obs or os.path.join(DATA, dataset, path)
        cfg = os.path.join(self.tmp, f"{name}.yaml")
        with open(cfg, "w") as f:
            f.write(f"station: {{id: {station}}}\n")
            f.write(f"input: {{kind: rinex, source: file, path: {obs}, "
                    f"nav: [{', '.join(os.path.join(DATA, dataset, n) for n in navs)}], pace: {pace}}}\n")
            f.write(f"outputs:\n  dds: {{enabled: true, domain: {DOMAIN}, topic: {topic}, "
                    f"profiles: {self.profiles('base')}}}\n  ntrip: {{enabled: false}}\n")
            f.write("log: {progress_interval_s: 0}\n")
        return self.spawn("cy-base", [os.path.join(BUILD, "canyon-base"), "--config", cfg, "--wait-for-clients",
                                      str(wait_clients), "--wait-timeout", "60"], os.path.join(self.tmp, f"{name}.log"))

    def probe(self, name, readers=1, role="rover", idle=6.0, duration=900, extra=()):
        out = open(os.path.join(self.tmp, f"{name}.json"), "w")
        cmd = [os.path.join(BUILD, "canyon-rtcm-probe"), "--profiles", self.profiles(role), "--domain", str(DOMAIN),
               "--readers", str(readers), "--idle", str(idle), "--duration", str(duration), *extra]
        return self.spawn("cy-rover", cmd, os.path.join(self.tmp, f"{name}.log"), stdout=out)

    def result(self, name):
        # Fast DDS logs its errors to standard output too: the result is the last line that is a JSON object.
        with open(os.path.join(self.tmp, f"{name}.json")) as f:
            text = "\n".join(ln for ln in f.read().splitlines() if ln.startswith("{"))
        if not text:
            with open(os.path.join(self.tmp, f"{name}.log")) as f:
                raise RuntimeError(f"{name}: no result; log:\n{f.read()[-3000:]}")
        return json.loads(text.splitlines()[-1])


def frames_of(logfile):
    """The frame count canyon-base reports when it stops ("stopped: 60 epochs, 219 frames, ...")."""
    with open(logfile) as f:
        text = f.read()
    at = text.rfind("stopped: ")
    if at < 0:
        raise RuntimeError(f"canyon-base did not stop cleanly:\n{text[-3000:]}")
    return int(text[at:].split(",")[1].split()[0])


def wait(p, timeout, what):
    try:
        return p.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        raise RuntimeError(f"{what} did not finish within {timeout} s")


def gps_seconds(epoch_line):
    """GPST seconds since 1980-01-06 of a RINEX 3 epoch line ("> 2023 01 08 10 00  0.0000000  0 20")."""
    f = epoch_line[1:].split()
    return (datetime.datetime(*map(int, f[:5])) - GPS_EPOCH).total_seconds() + float(f[5])


def slice_rinex(src, dst, start_s=None, seconds=None):
    """Writes the header and the epochs in [start_s, start_s + seconds) (GPST seconds; None: from the first epoch, to
    the end) of a RINEX 3 observation file: a receiver that observes from start_s on. Returns the epoch times kept."""
    with open(src) as f:
        lines = f.read().splitlines(keepends=True)
    body = next(i for i, ln in enumerate(lines) if "END OF HEADER" in ln) + 1
    out, kept, keep = lines[:body], [], False
    for ln in lines[body:]:
        if ln.startswith(">"):
            t = gps_seconds(ln)
            start_s = t if start_s is None else start_s
            keep = t >= start_s and (seconds is None or t < start_s + seconds)
            if keep:
                kept.append(t)
        if keep:
            out.append(ln)
    with open(dst, "w") as f:
        f.writelines(out)
    return kept


def header_position(path):
    with open(path) as f:
        for ln in f:
            if "APPROX POSITION XYZ" in ln:
                return [float(v) for v in ln.split()[:3]]
    raise RuntimeError(f"{path}: no APPROX POSITION XYZ")


def percentiles_ms(p):
    """A monitor percentile object (microseconds) in milliseconds."""
    return {k[:-3] + "_ms": round(p[k] / 1e3, 2) for k in ("p50_us", "p95_us", "p99_us", "max_us")} | \
        {"count": p["count"]}


class RoverHost:
    """The rover host's processes in cy-rover: `canyon rover` on the base's corrections, `canyon record` of its
    solutions (.pos, and .csv: every sample with its sequence number and arrival time), of the corrections (.rtcm3,
    what `canyon process` then runs on) and `canyon monitor --json`. Consumers outlive rover restarts
    (--until-gone false); their identity in the secure variant is `monitor` (read only)."""

    def __init__(self, setup, pace=1.0, base_wait_s=2.0, max_age_s=None):
        self.s = setup
        self.pace = pace
        self.base_wait_s = base_wait_s
        self.max_age_s = max_age_s
        self.base_pos = header_position(os.path.join(DATA, INSTINCT, INSTINCT_BASE))
        self.consumers = []
        self.proc = None
        self.runs = []  # (name, Popen, start monotonic ns)
        self.rss = []  # (monotonic ns, run name, VmRSS kB)
        self.path = lambda name: os.path.join(setup.tmp, name)

    def start_consumers(self):
        common = ["--domain", str(DOMAIN), "--profiles", self.s.profiles("monitor"), "--until-gone", "false"]
        record = os.path.join(BUILD, "canyon-record")
        for topic, out in (("canyon/solution", "solutions.pos"), ("canyon/solution", "solutions.csv"),
                           ("canyon/rtcm", "base.rtcm3")):
            self.consumers.append(self.s.spawn("cy-rover", [record, topic, "--out", self.path(out), *common],
                                               self.path(f"record-{out}.log")))
        self.consumers.append(self.s.spawn("cy-rover", [os.path.join(BUILD, "canyon-monitor"), "--json", "--interval",
                                                        "1", *common], self.path("monitor.log"),
                                           stdout=open(self.path("monitor.jsonl"), "w")))

    def start(self, name, rover_obs):
        """Starts `canyon rover` on `rover_obs` once the three solution readers are matched."""
        with open(os.path.join(REPO, "config", "rtk.yaml")) as f:
            estimator = f.read()
        if self.max_age_s is not None:
            estimator = "\n".join(f"  max_age_s: {self.max_age_s}" if ln.strip().startswith("max_age_s:") else ln
                                  for ln in estimator.splitlines())
        cfg = self.path(f"{name}.yaml")
        with open(cfg, "w") as f:
            f.write("estimator:\n" + "".join(f"  {ln}\n" for ln in estimator.splitlines()))
            f.write(f"  rover: {rover_obs}\n  nav: [{os.path.join(DATA, INSTINCT, INSTINCT_NAV)}]\n")
            f.write(f"  base_position: [{', '.join(map(str, self.base_pos))}]\n")
            f.write("rover_id: netns-rover\n")
            f.write(f"input: {{pace: {self.pace}, base: dds, base_wait_s: {self.base_wait_s}}}\n")
            f.write(f"dds: {{domain: {DOMAIN}, profiles: {self.s.profiles('rover')}}}\n")
        self.proc = self.s.spawn("cy-rover", [os.path.join(BUILD, "canyon-rover"), "--config", cfg,
                                              "--wait-for-subscribers", "3", "--wait-timeout", "60"],
                                 self.path(f"{name}.log"))
        self.runs.append((name, self.proc, time.monotonic_ns()))
        threading.Thread(target=self._sample_rss, args=(name, self.proc), daemon=True).start()
        return self.proc

    def _sample_rss(self, name, proc):
        # `ip netns exec` execs the rover: the Popen pid is the rover's.
        while proc.poll() is None:
            try:
                with open(f"/proc/{proc.pid}/status") as f:
                    kb = next(int(ln.split()[1]) for ln in f if ln.startswith("VmRSS:"))
                self.rss.append((time.monotonic_ns(), name, kb))
            except (OSError, StopIteration):
                pass
            time.sleep(1.0)

    def solutions(self):
        """The recorded samples: dicts with seq, gps_s, status, age_s, received_ns (every sample, in arrival order)."""
        rows = []
        try:
            with open(self.path("solutions.csv")) as f:
                header = next(f, "").strip().split(",")  # the columns by name (canyon record's CSV header)
                for line in f:
                    cells = line.strip().split(",")
                    if len(cells) == len(header):  # not a line cut short
                        c = dict(zip(header, cells))
                        rows.append({"seq": int(c["seq"]), "gps_s": int(c["gps_week"]) * 604800 + float(c["gps_tow_s"]),
                                     "status": int(c["status"]), "age_s": float(c["age_s"]),
                                     "received_ns": int(c["received_monotonic_ns"])})
        except OSError:
            pass
        return rows

    def data_time_now(self):
        """The rover's current GPST (seconds): its last solution's time advanced at the pace since it arrived."""
        rows = self.solutions()
        if not rows:
            raise RuntimeError("the rover has published no solution yet")
        last = rows[-1]
        return last["gps_s"] + (time.monotonic_ns() - last["received_ns"]) / 1e9 * self.pace

    def wait_fixed(self, after_ns, timeout_s):
        """The arrival (monotonic ns) of the first fixed solution received after `after_ns`, waiting at most
        timeout_s; None if none came."""
        until = time.monotonic() + timeout_s
        while True:
            fixed = [r["received_ns"] for r in self.solutions()
                     if r["received_ns"] >= after_ns and r["status"] == FIXED]
            if fixed or time.monotonic() > until:
                return fixed[0] if fixed else None
            time.sleep(0.2)

    def stop(self, timeout=30):
        """SIGTERM to the rover (it finishes the epochs in flight), then to the consumers."""
        if self.proc is not None and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            wait(self.proc, timeout, "canyon rover (SIGTERM)")
        time.sleep(1.0)  # the last solutions reach the recorders
        for p in self.consumers:
            p.send_signal(signal.SIGTERM)
        for p in self.consumers:
            wait(p, timeout, "canyon record / monitor (SIGTERM)")

    def monitor_last(self):
        with open(self.path("monitor.jsonl")) as f:
            lines = [ln for ln in f.read().splitlines() if ln.startswith("{")]
        if not lines:
            raise RuntimeError(f"canyon monitor wrote nothing (log: {self.path('monitor.log')})")
        return json.loads(lines[-1])


def sequence_accounting(rows, runs):
    """Per rover run (the sequence numbers restart at 0 with the process): sequence numbers contiguous from 0 and
    epoch times 1 s apart; one dict per run."""
    split, current = [], []
    for r in rows:
        if current and r["seq"] == 0:
            split.append(current)
            current = []
        current.append(r)
    if current:
        split.append(current)
    out = []
    for (name, _, _), run_rows in zip(runs, split + [[]] * (len(runs) - len(split))):
        seqs = [r["seq"] for r in run_rows]
        steps = {round(b["gps_s"] - a["gps_s"], 3) for a, b in zip(run_rows, run_rows[1:])}
        out.append({"run": name, "solutions": len(run_rows), "contiguous": seqs == list(range(len(seqs))),
                    "epoch_steps_s": sorted(steps), "ok": bool(run_rows) and seqs == list(range(len(seqs)))
                    and steps <= {1.0}})
    return out


def compare_pos(recorded, processed):
    """Records (lines not starting with %) of two .pos files: equal byte for byte, and the count of each."""
    def records(path):
        with open(path) as f:
            return [ln for ln in f.read().splitlines(keepends=True) if not ln.startswith("%")]
    a, b = records(recorded), records(processed)
    first_diff = next((i for i, (x, y) in enumerate(zip(a, b)) if x != y), None)
    return {"recorded": len(a), "process": len(b), "equal": a == b and len(a) > 0,
            "first_difference": None if first_diff is None else {"recorded": a[first_diff].rstrip(),
                                                                 "process": b[first_diff].rstrip()}}


def rover(args, tmp):
    """canyon-base (instinct base, at `pace`) in cy-base; canyon rover, record and monitor in cy-rover over the link.
    The recorded .pos must equal `canyon process` on the rover file and the recorded corrections, byte for byte."""
    rover_obs = os.path.join(tmp, "rover.obs")
    epochs = slice_rinex(os.path.join(DATA, INSTINCT, INSTINCT_ROVER), rover_obs, seconds=args.seconds or None)
    with Setup(tmp, secure=args.secure, link=args.link) as s:
        host = RoverHost(s, pace=args.pace)
        # The base first: it starts once the rover's and the RTCM recorder's readers are matched.
        base = s.base("base", dataset=INSTINCT, pace=args.pace, wait_clients=2)
        host.start_consumers()
        rov = host.start("rover", rover_obs)
        wait(rov, len(epochs) / args.pace + 120, "canyon rover")
        if base.poll() is None:  # the rover file may be shorter than the base's
            base.send_signal(signal.SIGTERM)
        wait(base, 30, "canyon-base")
        host.stop()
        monitor = host.monitor_last()
        rows = host.solutions()
        stats = link_stats()
    process_pos = os.path.join(tmp, "process.pos")
    r = subprocess.run([os.path.join(BUILD, "canyon"), "process", "-q", "--config",
                        os.path.join(REPO, "config", "rtk.yaml"), "--rover", rover_obs, "--base",
                        os.path.join(tmp, "base.rtcm3"), "--nav", os.path.join(DATA, INSTINCT, INSTINCT_NAV),
                        "--base-pos", ",".join(map(str, host.base_pos)), "--out", process_pos],
                       text=True, capture_output=True)
    if r.returncode != 0:
        raise RuntimeError(f"canyon process failed: {r.stderr[-2000:]}")
    same = compare_pos(os.path.join(tmp, "solutions.pos"), process_pos)
    accounting = sequence_accounting(rows, host.runs)
    statuses = {str(k): sum(1 for x in rows if x["status"] == k) for k in sorted({x["status"] for x in rows})}
    checks = {
        "rover_exit_0": rov.returncode == 0,
        "pos_equals_canyon_process": same["equal"],
        "one_solution_per_epoch": accounting[0]["ok"] and accounting[0]["solutions"] == len(epochs),
        "monitor_lost_none": monitor["lost_solutions"] == 0 and monitor["solutions"] == len(epochs),
    }
    ok = all(checks.values())
    print(json.dumps({"scenario": "rover", "secure": args.secure, "pace": args.pace, "link": args.link,
                      "rover_epochs": len(epochs), "pos": same, "statuses": statuses,
                      "latency": {k: percentiles_ms(monitor[k]) for k in ("end_to_end", "base_to_solution",
                                                                           "delivery")},
                      "base_late": monitor["drops"]["base_late"],
                      "link_lost_packets": {k: v.get("lost", 0) for k, v in stats.items()},
                      "checks": checks, "ok": ok}), flush=True)
    return ok


def relay(args, tmp):
    """One base run to N subscribers over the link."""
    with Setup(tmp, profile=args.profile, secure=args.secure, link=args.link) as s:
        probe = s.probe("relay", readers=args.subscribers, idle=8.0)
        base = s.base("base", pace=args.pace, wait_clients=args.subscribers)
        wait(base, 300, "canyon-base")
        wait(probe, 120, "canyon-rtcm-probe")
        frames = frames_of(os.path.join(tmp, "base.log"))
        r = s.result("relay")
        stats = link_stats()
    ok = (r["min_received"] == frames and r["gaps"] == 0 and r["out_of_order"] == 0 and r["duplicates"] == 0
          and r["bad"] == 0)
    out = {"scenario": "relay", "subscribers": args.subscribers, "secure": args.secure, "profile": args.profile,
           "link": args.link, "frames_sent": frames, "min_received": r["min_received"], "gaps": r["gaps"],
           "out_of_order": r["out_of_order"], "duplicates": r["duplicates"], "bad": r["bad"],
           "latency_ms": r["latency"], "link_lost_packets": {k: v.get("lost", 0) for k, v in stats.items()},
           "link_packets": {k: v.get("packets", 0) for k, v in stats.items()}, "ok": ok}
    print(json.dumps(out), flush=True)
    return ok


def security(args, tmp):
    """Intruders reach no subscriber; tampered packets never become frames on the secure stream."""
    results = []
    with Setup(tmp, secure=True) as s:
        # Legitimate base and rover subscriber, plus a second listener: the monitor identity (read-only).
        probe = s.probe("legit", readers=1, idle=10.0, extra=["--station", "3034"])
        # Intruders publish forged frames (station 4095) on canyon/rtcm for the whole run.
        plain = s.spawn("cy-rover", [os.path.join(BUILD, "canyon-rtcm-probe"), "--mode", "inject", "--profiles",
                                     os.path.join(REPO, "deploy", "dds", "wan-initial-peers.xml"), "--domain",
                                     str(DOMAIN), "--count", "40", "--wait", "5"],
                        os.path.join(tmp, "inject-plain.log"), stdout=open(os.path.join(tmp, "inject-plain.json"), "w"))
        rogue = s.spawn("cy-rover", [os.path.join(BUILD, "canyon-rtcm-probe"), "--mode", "inject", "--profiles",
                                     s.profiles("intruder"), "--domain", str(DOMAIN), "--count", "40", "--wait", "5"],
                        os.path.join(tmp, "inject-rogue.log"), stdout=open(os.path.join(tmp, "inject-rogue.json"), "w"))
        monitor = s.spawn("cy-rover", [os.path.join(BUILD, "canyon-rtcm-probe"), "--mode", "inject", "--profiles",
                                       s.profiles("monitor"), "--domain", str(DOMAIN), "--count", "40", "--wait", "5"],
                          os.path.join(tmp, "inject-monitor.log"),
                          stdout=open(os.path.join(tmp, "inject-monitor.json"), "w"))
        # Eavesdroppers: no security at all, and the rogue identity, try to read the corrections.
        eaves_plain = s.spawn("cy-rover", [os.path.join(BUILD, "canyon-rtcm-probe"), "--profiles",
                                           os.path.join(REPO, "deploy", "dds", "wan-initial-peers.xml"), "--domain",
                                           str(DOMAIN), "--duration", "25", "--idle", "25", "--station", "3034"],
                              os.path.join(tmp, "eaves-plain.log"),
                              stdout=open(os.path.join(tmp, "eaves-plain.json"), "w"))
        eaves_rogue = s.spawn("cy-rover", [os.path.join(BUILD, "canyon-rtcm-probe"), "--profiles",
                                           s.profiles("intruder"), "--domain", str(DOMAIN), "--duration", "25",
                                           "--idle", "25", "--station", "3034"],
                              os.path.join(tmp, "eaves-rogue.log"),
                              stdout=open(os.path.join(tmp, "eaves-rogue.json"), "w"))
        time.sleep(2.0)
        # Corrupt 2 % of the packets in both directions: AES-GCM must reject every tampered one.
        twohost("set", "corrupt=0.02")
        base = s.base("base", pace=5.0, wait_clients=1)
        wait(base, 300, "canyon-base")
        frames = frames_of(os.path.join(tmp, "base.log"))
        for p, what in ((probe, "legit probe"), (plain, "plain injector"), (rogue, "rogue injector"),
                        (monitor, "monitor injector"), (eaves_plain, "plain eavesdropper"),
                        (eaves_rogue, "rogue eavesdropper")):
            wait(p, 120, what)
        legit = s.result("legit")
        corrupted = sum(v.get("corrupted", 0) for v in link_stats().values())

        def injected(name):
            with open(os.path.join(tmp, f"{name}.json")) as f:
                lines = [ln for ln in f.read().splitlines() if ln.startswith("{")]
            return json.loads(lines[-1]) if lines else {}

        inj = {n: injected(f"inject-{n}") for n in ("plain", "rogue", "monitor")}
        eav = {n: s.result(f"eaves-{n}") for n in ("plain", "rogue")}
    checks = {
        "legit_receives_every_frame": legit["min_received"] == frames and legit["gaps"] == 0,
        "no_forged_frame_used": legit["foreign"] == 0,
        "no_tampered_frame_delivered": legit["bad"] == 0,
        "packets_corrupted_on_the_link": corrupted > 0,
        "plain_intruder_wrote": inj["plain"].get("written", 0) > 0,
        "rogue_intruder_wrote": inj["rogue"].get("written", 0) > 0,
        "monitor_identity_cannot_publish": inj["monitor"].get("writer") is False,
        "plain_eavesdropper_reads_nothing": eav["plain"]["min_received"] == 0,
        "rogue_eavesdropper_reads_nothing": eav["rogue"]["min_received"] == 0,
    }
    ok = all(checks.values())
    print(json.dumps({"scenario": "security", "frames_sent": frames, "legit_received": legit["min_received"],
                      "packets_corrupted": corrupted, "injectors": inj,
                      "eavesdroppers": {n: {"base_frames": e["min_received"], "forged_frames": e["foreign"]}
                                        for n, e in eav.items()},
                      "checks": checks, "ok": ok}), flush=True)
    return ok


def read_arrivals(path):
    rows = []
    with open(path) as f:
        next(f, None)
        for line in f:
            parts = line.strip().split(",")
            if len(parts) == 4:
                rows.append((int(parts[0]), int(parts[1])))  # (arrival monotonic ns, sequence number)
    return rows


def faults(args, tmp):
    """Faults applied to the running base -> rover stream (and a probe subscriber that counts every frame): the link
    faults, the rover killed and restarted, the base killed and restarted. Probe recovery = first frame after the link
    is restored (or the base restarted) minus that instant; rover recovery = first fixed solution after it."""
    if args.short:
        plan = [("loss20", ["loss=0.2"], 6), ("outage", ["outage=1"], 6),
                ("dup_reorder_corrupt", ["duplicate=0.05", "reorder=0.05", "corrupt=0.02"], 5)]
        steady, restart_pause, base2_seconds, max_age_s = 3, 2, 20, 3.0
    else:
        plan = [("loss20", ["loss=0.2"], 60), ("outage", ["outage=1"], 60),
                ("dup_reorder_corrupt", ["duplicate=0.05", "reorder=0.05", "corrupt=0.02"], 60)]
        steady, restart_pause, base2_seconds, max_age_s = 20, 5, 60, None  # rtk.max_age_s as shipped: 30 s
    refix_s = ROVER_EXPECTATIONS["refix_within_s"]
    clear = ["loss=0.01", "outage=0", "duplicate=0", "reorder=0", "corrupt=0"]
    events = []
    alive = {}
    with Setup(tmp, secure=args.secure) as s:
        # The probe outlasts the longest fault without a frame.
        probe = s.probe("faults", readers=1, idle=max(sec for _, _, sec in plan) + 15.0,
                        extra=["--arrivals", os.path.join(tmp, "arrivals.csv")])
        host = RoverHost(s, pace=1.0, max_age_s=max_age_s)
        base = s.base("base1", dataset=INSTINCT, pace=1.0, wait_clients=3)
        host.start_consumers()
        host.start("rover1", os.path.join(DATA, INSTINCT, INSTINCT_ROVER))
        first_fix = host.wait_fixed(0, 90)
        if first_fix is None:
            raise RuntimeError(f"the rover never fixed before the faults (log: {host.path('rover1.log')})")
        log(f"rover fixed {(first_fix - host.runs[0][2]) / 1e9:.1f} s after it started")

        def settle(restored_ns):
            """Steady time after a fault: at least `steady` s, and until the rover fixed again (at most refix_s)."""
            time.sleep(steady)
            host.wait_fixed(restored_ns, max(0.0, refix_s - (time.monotonic_ns() - restored_ns) / 1e9) + 1.0)

        for name, kv, seconds in plan:
            t0 = time.monotonic_ns()
            twohost("set", *kv)
            time.sleep(seconds)
            twohost("set", *clear)
            events.append({"fault": name, "start_ns": t0, "restored_ns": time.monotonic_ns(), "seconds": seconds})
            alive[name] = host.proc.poll() is None
            settle(events[-1]["restored_ns"])
        # The rover killed hard and restarted: a receiver observes from now on (the rover file from the current time).
        t0 = time.monotonic_ns()
        host.proc.kill()
        host.proc.wait()
        time.sleep(restart_pause)
        # Its start-up (process, participant, matching its subscribers) takes about 0.5 s: a rover file starting later
        # than the base's current time would run ahead of the base and wait out base_wait_s at every epoch.
        start_s = host.data_time_now() + 1.0
        slice_rinex(os.path.join(DATA, INSTINCT, INSTINCT_ROVER), os.path.join(tmp, "rover2.obs"), start_s=start_s)
        restarted = time.monotonic_ns()
        host.start("rover2", os.path.join(tmp, "rover2.obs"))
        events.append({"fault": "rover_killed_restarted", "start_ns": t0, "restored_ns": restarted,
                       "seconds": restart_pause, "rover_only": True})
        settle(restarted)
        # The base killed hard and restarted: it goes on from the current time.
        t0 = time.monotonic_ns()
        base.kill()
        base.wait()
        time.sleep(restart_pause)
        slice_rinex(os.path.join(DATA, INSTINCT, INSTINCT_BASE), os.path.join(tmp, "base2.obs"),
                    start_s=host.data_time_now() + 1.0, seconds=base2_seconds)
        restarted = time.monotonic_ns()
        base2 = s.base("base2", dataset=INSTINCT, pace=1.0, wait_clients=3, obs=os.path.join(tmp, "base2.obs"))
        events.append({"fault": "base_killed_restarted", "start_ns": t0, "restored_ns": restarted,
                       "seconds": restart_pause})
        wait(base2, base2_seconds + 90, "restarted canyon-base")
        alive["base_killed_restarted"] = host.proc.poll() is None
        frames2 = frames_of(os.path.join(tmp, "base2.log"))
        time.sleep(2.0)
        probe.send_signal(signal.SIGTERM)
        wait(probe, 30, "canyon-rtcm-probe")
        rover_rc = host.proc.poll()
        host.stop()
        r = s.result("faults")
        stats = link_stats()
    arrivals = read_arrivals(os.path.join(tmp, "arrivals.csv"))
    rows = host.solutions()
    ok = True
    results = []
    for e in events:
        after = [t for t, _ in arrivals if t >= e["restored_ns"]]
        during = [t for t, _ in arrivals if e["start_ns"] <= t < e["restored_ns"]]
        window = [t for t, _ in arrivals if e["start_ns"] - 1e9 <= t <= e["restored_ns"] + steady * 1e9]
        stall = max((b - a for a, b in zip(window, window[1:])), default=0) / 1e9
        recovery = (after[0] - e["restored_ns"]) / 1e9 if after else None
        fixed_after = [x["received_ns"] for x in rows if x["received_ns"] >= e["restored_ns"] and x["status"] == FIXED]
        refix = (fixed_after[0] - e["restored_ns"]) / 1e9 if fixed_after else None
        in_fault = [x["status"] for x in rows if e["start_ns"] <= x["received_ns"] < e["restored_ns"]]
        res = {"fault": e["fault"], "seconds": e["seconds"],
               "rover_refix_s": None if refix is None else round(refix, 2),
               "rover_statuses_during": {str(k): in_fault.count(k) for k in sorted(set(in_fault))},
               "rover_alive_after": alive.get(e["fault"], True)}
        if not e.get("rover_only"):
            res |= {"frames_during": len(during), "recovery_s": None if recovery is None else round(recovery, 3),
                    "longest_stall_s": round(stall, 3)}
            ok = ok and recovery is not None and recovery <= 10.0
        ok = ok and refix is not None and refix <= refix_s and res["rover_alive_after"]
        results.append(res)
    # The restarted base's run arrives complete and in order (sequence numbers 0, 1, ... again).
    reader = r["readers"][0]
    restart_ns = events[-1]["restored_ns"]
    seqs_after = [q for t, q in arrivals if t >= restart_ns]
    complete_after_restart = reader["restarts"] >= 1 and seqs_after == list(range(frames2))
    # Without security a corrupted packet (UDP checksum cleared) reaches the application as a sample: the RTCM
    # CRC-24Q rejects it and that frame is lost for good (counted in gaps). With security AES-GCM rejects the packet
    # and the reliable protocol repeats it: nothing tampered is delivered. (Frames sent during an outage longer than
    # the participants' lease are lost either way: see deploy/README.md.)
    ok = ok and complete_after_restart and (not args.secure or r["bad"] == 0)
    # The rover: one solution per epoch in each run, corrections older than the maximum age never used, memory flat.
    max_age = max_age_s if max_age_s is not None else 30.0
    accounting = sequence_accounting(rows, host.runs)
    stale = [x for x in rows if x["age_s"] > max_age]
    stale_used = [x for x in stale if x["status"] in (FIXED, FLOAT)]
    rss_mb = {}
    for name, _, start_ns in host.runs:
        run_fix = next((x["received_ns"] for x in rows if x["received_ns"] >= start_ns and x["status"] == FIXED), None)
        samples = [kb for t, n, kb in host.rss if n == name and run_fix is not None and t >= run_fix]
        if samples:
            rss_mb[name] = {"first": round(samples[0] / 1024, 1), "max": round(max(samples) / 1024, 1),
                            "last": round(samples[-1] / 1024, 1), "samples": len(samples)}
    growth = max((round(v["last"] - v["first"], 1) for v in rss_mb.values()), default=None)
    rover_checks = {
        "every_epoch_one_solution": all(a["ok"] for a in accounting) and len(accounting) == len(host.runs),
        "never_stops": all(alive.values()) and rover_rc is None,
        "refix_within_s": all(x["rover_refix_s"] is not None and x["rover_refix_s"] <= refix_s for x in results),
        "stale_corrections_unused": len(stale) > 0 and not stale_used,
        "max_rss_growth_mb": growth is not None and growth <= ROVER_EXPECTATIONS["max_rss_growth_mb"],
    }
    ok = ok and all(rover_checks.values())
    print(json.dumps({"scenario": "faults", "short": args.short, "secure": args.secure, "results": results,
                      "restarted_run_complete": complete_after_restart, "frames_restarted_run": frames2,
                      "received_total": reader["received"], "duplicates_delivered": r["duplicates"],
                      "tampered_delivered_rejected_by_crc": r["bad"], "frames_lost": r["gaps"],
                      "rover": {"first_fix_s": round((first_fix - host.runs[0][2]) / 1e9, 2),
                                "runs": accounting, "max_age_s": max_age, "epochs_beyond_max_age": len(stale),
                                "stale_used": len(stale_used), "rss_mb": rss_mb, "rss_growth_mb": growth,
                                "checks": rover_checks},
                      "link": {k: {f: v.get(f, 0) for f in ("packets", "lost", "outage_drops", "duplicated",
                                                                 "reordered", "corrupted")} for k, v in stats.items()},
                      "ok": ok}), flush=True)
    return ok


def live(args, tmp):
    with Setup(tmp, secure=args.secure) as s:
        probe = s.probe("live", readers=1, idle=30.0, duration=args.seconds,
                        extra=["--json-lines", os.path.abspath(args.json_lines), "--link-stats",
                               os.path.join(STATE, "stats-cy-base.json")])
        s.base("base", dataset="matrtklib-static", pace=1.0, wait_clients=1)
        start = time.monotonic()
        while probe.poll() is None and time.monotonic() - start < args.seconds + 5:
            phase = (time.monotonic() - start) % 40.0
            want = ["loss=0.2"] if 10 <= phase < 20 else (["outage=1"] if 20 <= phase < 30 else ["loss=0.01", "outage=0"])
            twohost("set", *want)
            time.sleep(1.0)
        wait(probe, 60, "canyon-rtcm-probe")
    print(json.dumps({"scenario": "live", "json_lines": args.json_lines, "ok": True}), flush=True)
    return True


def scenario_dir(tmp, name):
    path = os.path.join(tmp, name)
    os.makedirs(path, exist_ok=True)
    return path


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("relay")
    r.add_argument("--subscribers", type=int, default=4)
    r.add_argument("--secure", action="store_true")
    r.add_argument("--profile", default="wan-initial-peers",
                   choices=["lan", "wan-initial-peers", "wan-discovery-server"])
    r.add_argument("--pace", type=float, default=5.0)
    r.add_argument("--link", nargs="*", default=LINK_20KM)
    sub.add_parser("security")
    rv = sub.add_parser("rover")
    rv.add_argument("--secure", action="store_true")
    rv.add_argument("--pace", type=float, default=1.0)
    rv.add_argument("--seconds", type=float, default=0.0, help="the rover file's first S seconds (0: all 601)")
    rv.add_argument("--link", nargs="*", default=LINK_20KM)
    f = sub.add_parser("faults")
    f.add_argument("--short", action="store_true")
    f.add_argument("--secure", action="store_true")
    lv = sub.add_parser("live")
    lv.add_argument("--json-lines", required=True)
    lv.add_argument("--seconds", type=float, default=120.0)
    lv.add_argument("--secure", action="store_true")
    sub.add_parser("short")
    args = parser.parse_args()
    why = check_environment()
    if why:
        print(f"SKIP: {why}", flush=True)
        return SKIP
    tmp = tempfile.mkdtemp(prefix="canyon-netns-")
    try:
        scenarios = {"relay": relay, "security": security, "rover": rover, "faults": faults, "live": live}
        if args.cmd in scenarios:
            ok = scenarios[args.cmd](args, tmp)
        else:
            # Each scenario in a folder of its own (KEEP=1 keeps them all).
            ok = relay(argparse.Namespace(subscribers=4, secure=False, profile="wan-initial-peers", pace=5.0,
                                          link=LINK_20KM), scenario_dir(tmp, "relay"))
            ok = security(args, scenario_dir(tmp, "security")) and ok
            ok = rover(argparse.Namespace(secure=False, pace=4.0, seconds=120.0, link=LINK_20KM),
                       scenario_dir(tmp, "rover")) and ok
            ok = faults(argparse.Namespace(short=True, secure=False), scenario_dir(tmp, "faults")) and ok
    except (RuntimeError, subprocess.CalledProcessError, OSError, ValueError) as e:
        detail = getattr(e, "stderr", "") or ""
        print(f"FAILED: {e} {detail}", flush=True)
        ok = False
    finally:
        try:
            twohost("down")
        except subprocess.CalledProcessError:
            pass
        if os.environ.get("KEEP"):
            log(f"kept {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
