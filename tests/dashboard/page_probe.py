#!/usr/bin/python3
"""Watch the dashboard page in headless Chromium over the DevTools protocol: start Chromium on the page, read the
counters the page keeps in #test-status (updates, first-t, last-t, charts, drawn) once the first snapshot has arrived
and again --gap seconds later in the same page, save a screenshot, print both readings as one JSON object.

--dump-dom cannot do this: it dumps at the page's load event, which comes ~1 s after the start whether or not the
event stream has delivered anything yet (about half the loads on this machine found no snapshot), and
--virtual-time-budget never ends while an event stream is open.
  page_probe.py --chromium PATH --url URL --profile DIR --screenshot PNG [--gap S] [--wait S]
Exit 0 with the readings, 1 with the reason on stderr.
"""
import argparse
import base64
import json
import re
import signal
import subprocess
import sys
import threading
import time
import urllib.request

import websocket  # Debian: python3-websocket

STATUS_JS = "JSON.stringify(Object.assign({}, document.getElementById('test-status').dataset))"


class DevTools:
    """One page target of a Chromium started with --remote-debugging-port=0."""

    def __init__(self, chromium, url, profile, wait_s):
        self.process = subprocess.Popen(
            [chromium, "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
             "--hide-scrollbars", "--window-size=1500,1500", "--remote-debugging-port=0",
             "--user-data-dir=" + profile, url],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self.stderr_tail = []
        self.socket = None
        self.next_id = 0
        try:
            port = self._port(wait_s)
            # Keep reading Chromium's stderr (its last lines for the report): a full pipe would block it.
            threading.Thread(target=self._drain, daemon=True).start()
            page = self._page_target(port, url, wait_s)
            self.socket = websocket.create_connection(page["webSocketDebuggerUrl"], timeout=30)
        except BaseException:
            self.close()
            raise

    def _drain(self):
        for line in self.process.stderr:
            self.stderr_tail = (self.stderr_tail + [line.rstrip()])[-10:]

    def _port(self, wait_s):
        deadline = time.monotonic() + wait_s
        while time.monotonic() < deadline:
            line = self.process.stderr.readline()
            if not line:
                break
            self.stderr_tail = (self.stderr_tail + [line.rstrip()])[-10:]
            match = re.search(r"DevTools listening on ws://[^:]+:(\d+)/", line)
            if match:
                return int(match.group(1))
        raise RuntimeError("Chromium did not open its DevTools port (exit status %s): %s"
                           % (self.process.poll(), " | ".join(self.stderr_tail[-3:])))

    @staticmethod
    def _page_target(port, url, wait_s):
        deadline = time.monotonic() + wait_s
        while time.monotonic() < deadline:
            with urllib.request.urlopen("http://127.0.0.1:%d/json/list" % port, timeout=5) as reply:
                for target in json.load(reply):
                    if target.get("type") == "page" and target.get("url", "").startswith(url):
                        return target
            time.sleep(0.2)
        raise RuntimeError("Chromium opened no page for " + url)

    def call(self, method, **params):
        self.next_id += 1
        self.socket.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            message = json.loads(self.socket.recv())
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise RuntimeError("%s: %s" % (method, message["error"]))
                return message["result"]

    def status(self):
        result = self.call("Runtime.evaluate", expression=STATUS_JS, returnByValue=True)
        value = result.get("result", {}).get("value")
        return json.loads(value) if value else {}

    def close(self):
        try:
            if self.socket is not None:
                self.socket.close()
        finally:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()


def first_snapshot(page, wait_s):
    """The page's counters once it has drawn at least one snapshot (None after wait_s)."""
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline:
        status = page.status()
        if int(status.get("updates", "0") or 0) > 0:
            return status
        time.sleep(0.2)
    return None


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--chromium", required=True)
    p.add_argument("--url", required=True)
    p.add_argument("--profile", required=True)
    p.add_argument("--screenshot", required=True)
    p.add_argument("--gap", type=float, default=3.0, help="seconds between the two readings")
    p.add_argument("--wait", type=float, default=60.0, help="seconds to wait for Chromium and the first snapshot")
    args = p.parse_args()
    # A timeout's SIGTERM unwinds through the finally blocks, which stop Chromium.
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(1))
    try:
        page = DevTools(args.chromium, args.url, args.profile, args.wait)
    except (RuntimeError, OSError, websocket.WebSocketException) as e:
        print("page_probe: %s" % e, file=sys.stderr)
        return 1
    try:
        first = first_snapshot(page, args.wait)
        if first is None:
            print("page_probe: the page drew no snapshot in %.0f s: %s" % (args.wait, page.status()), file=sys.stderr)
            return 1
        time.sleep(args.gap)
        second = page.status()
        png = page.call("Page.captureScreenshot", format="png")["data"]
        with open(args.screenshot, "wb") as f:
            f.write(base64.b64decode(png))
        print(json.dumps({"first": first, "second": second}))
        return 0
    except (RuntimeError, OSError, websocket.WebSocketException) as e:
        print("page_probe: %s" % e, file=sys.stderr)
        return 1
    finally:
        page.close()


if __name__ == "__main__":
    sys.exit(main())
