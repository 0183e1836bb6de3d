"""Where the browser's CPU goes for a kd change (issue 42): the page of ``phong-explorer web``
(the teapot at resolution 56, as bench_web), ``--repeat`` kd changes, each as bench_web makes
it (``window.trame.state.set('kd_step', ...)``, waiting for the new picture), attributed

- per process and thread: each Chromium process's threads' CPU (``/proc/<pid>/task``, user and
  system ticks) from before the first change to after the last, per change;
- per kind on the renderer's main thread: Chrome's trace (devtools.timeline and toplevel
  categories over the browser's DevTools websocket) summed by event name (outermost event of
  a name on a thread; its thread time ``tdur``), per change;
- per script function: the page's CPU profile (CDP ``Profiler``), self time per function;
- the wire: the state keys each server message carries back (``trame.state.topic``: the
  websocket frames the page received, unchunked), per change;
- the page: DOM mutations per change (a MutationObserver on the document), by the
  ``aria-label`` (or tag and class) of the nearest labelled ancestor.

    python benchmarks/trace_web_change.py --repeat 10

The load average is printed with the figures (a loaded machine stretches wall times, not the
CPU per change much)."""

from __future__ import annotations

import argparse
import base64
import collections
import json
import os
import sys
import tempfile
import threading
import time
import urllib.request
from pathlib import Path

import msgpack
import websocket
from bench_web import (
    REPORT_JS,
    SAMPLE_JS,
    browser,
    descendants,
    free_port,
    size_view,
    start_server,
    stop,
    wait_url,
)
from wslink.chunking import UnChunker

CATEGORIES = [
    "toplevel",
    "devtools.timeline",
    "disabled-by-default-devtools.timeline",
    "v8.execute",
    "blink",
    "cc",
    "gpu",
    "viz",
]

#: a MutationObserver on the whole document; window.muts: the mutations since the last read,
#: each named by the nearest ancestor with an aria-label (else its tag and first class)
OBSERVE_JS = """
window.muts = [];
const name = (n) => {
  for (let e = n.nodeType === 1 ? n : n.parentElement; e; e = e.parentElement) {
    const a = e.getAttribute && e.getAttribute('aria-label');
    if (a) return a;
  }
  const e = n.nodeType === 1 ? n : n.parentElement;
  return e ? e.tagName.toLowerCase() + '.' + (e.classList[0] || '') : '?';
};
new MutationObserver((ms) => {
  for (const m of ms) window.muts.push(m.type + ' ' + name(m.target)
    + (m.type === 'attributes' ? ' <' + m.target.tagName.toLowerCase() + '>@' + m.attributeName
       + (m.oldValue === m.target.getAttribute(m.attributeName) ? ' (same)' : '') : ''));
}).observe(document, {subtree: true, childList: true, attributes: true, characterData: true,
  attributeOldValue: true});
"""


class Cdp:
    """The browser's DevTools websocket: commands, and the events it sends (kept by a
    reader thread)."""

    def __init__(self, address: str):
        with urllib.request.urlopen(f"http://{address}/json/version") as r:
            url = json.load(r)["webSocketDebuggerUrl"]
        self.ws = websocket.create_connection(url, suppress_origin=True, timeout=600)
        self.n, self.replies, self.events = 0, {}, []
        self.lock = threading.Lock()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        while True:
            try:
                msg = json.loads(self.ws.recv())
            except Exception:  # (closed)
                return
            with self.lock:
                if "id" in msg:
                    self.replies[msg["id"]] = msg
                else:
                    self.events.append(msg)

    def call(self, method, params=None, session=None, timeout=120):
        self.n += 1
        n = self.n
        msg = {"id": n, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        self.ws.send(json.dumps(msg))
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            with self.lock:
                if n in self.replies:
                    got = self.replies.pop(n)
                    if "error" in got:
                        raise RuntimeError(f"{method}: {got['error']}")
                    return got.get("result", {})
            time.sleep(0.01)
        raise TimeoutError(method)

    def take(self, method):
        with self.lock:
            got = [e for e in self.events if e.get("method") == method]
            self.events = [e for e in self.events if e.get("method") != method]
        return got


def thread_ticks(pids) -> dict:
    """(process kind, thread name) -> CPU ms used so far, over ``pids``' threads."""
    tick = 1e3 / os.sysconf("SC_CLK_TCK")
    out = collections.Counter()
    for pid in pids:
        try:
            cmd = open(f"/proc/{pid}/cmdline", "rb").read().replace(b" ", b"\0").split(b"\0")
        except OSError:
            continue
        kind = next((a.decode()[7:] for a in cmd if a.startswith(b"--type=")), None)
        if kind is None:
            kind = os.path.basename(cmd[0].decode()) if cmd and cmd[0] else "?"
        if kind == "utility":
            sub = next((a.decode() for a in cmd if a.startswith(b"--utility-sub-type=")), "")
            kind = "utility " + sub.split("=")[-1].split(".")[-2] if sub else kind
        try:
            tids = os.listdir(f"/proc/{pid}/task")
        except OSError:
            continue
        for tid in tids:
            try:
                with open(f"/proc/{pid}/task/{tid}/stat") as f:
                    text = f.read()
            except OSError:
                continue
            comm = text[text.index("(") + 1 : text.rindex(")")]
            comm = comm.rstrip("0123456789") or comm  # (ThreadPoolForeg..., numbered pools)
            fields = text.rsplit(")", 1)[1].split()
            out[(kind, comm)] += (int(fields[11]) + int(fields[12])) * tick
    return out


def trace_kinds(events: list) -> tuple[dict, dict]:
    """(thread name per (pid, tid), and (pid, tid) -> name -> thread ms of the outermost
    events of each name) from Chrome's trace events."""
    names, procs = {}, {}
    for e in events:
        if e.get("ph") == "M" and e.get("name") == "thread_name":
            names[(e["pid"], e["tid"])] = e["args"]["name"]
        if e.get("ph") == "M" and e.get("name") == "process_name":
            procs[e["pid"]] = e["args"]["name"]
    sums = collections.defaultdict(collections.Counter)
    spans = collections.defaultdict(list)
    for e in events:
        if e.get("ph") == "X" and "tdur" in e:
            spans[(e["pid"], e["tid"])].append((e["ts"], e["ts"] + e["dur"], e["name"], e["tdur"]))
    for key, evs in spans.items():
        evs.sort()
        open_until = {}  # name -> end of the outermost open event of that name
        for t0, t1, name, tdur in evs:
            if open_until.get(name, -1) > t0:
                continue  # nested in one of its own name
            open_until[name] = t1
            sums[key][name] += tdur / 1e3
    label = {k: f"{procs.get(k[0], k[0])} / {names.get(k, k[1])}" for k in sums}
    return label, sums


def profile_self(profile: dict, top: int) -> list:
    """The page's CPU profile: (self ms, function @ url:line) of the ``top`` functions."""
    nodes = {n["id"]: n for n in profile["nodes"]}
    self_us = collections.Counter()
    deltas = profile.get("timeDeltas", [])
    for i, s in enumerate(profile.get("samples", [])):
        dt = deltas[i + 1] if i + 1 < len(deltas) else 0
        f = nodes[s]["callFrame"]
        url = f.get("url", "").rsplit("/", 1)[-1].split("?")[0]
        where = f"{f.get('functionName') or '(anonymous)'} @ {url}:{f.get('lineNumber', -1) + 1}"
        self_us[where] += dt
    return [(us / 1e3, w) for w, us in self_us.most_common(top)]


def _short(v):
    """A state value as the report shows it (long ones cut)."""
    t = repr(v)
    return t if len(t) <= 40 else t[:37] + "..."


def wire_keys(frames: list) -> list:
    """The state keys each ``trame.state.topic`` message received carries (the page's
    websocket frames, binary, unchunked)."""
    un = UnChunker()
    seen_ids = collections.Counter()
    un.set_max_message_size(1 << 30)
    out = []
    for f in frames:
        r = f["params"]["response"]
        if r.get("opcode") != 2:
            continue
        msg = un.process_chunk(base64.b64decode(r["payloadData"]))
        if msg is None:
            continue
        msg = msg if isinstance(msg, dict) else msgpack.unpackb(msg, strict_map_key=False)
        if isinstance(msg, dict):
            seen_ids[":".join(str(msg.get("id", "")).split(":")[:2])] += 1
        if isinstance(msg, dict) and "trame.state.topic" in str(msg.get("id", "")):
            res = msg.get("result")
            if isinstance(res, dict):
                out.append({k: _short(v) for k, v in sorted(res.items())})
    print("#   messages:", dict(seen_ids), file=sys.stderr)
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=10)
    ap.add_argument("--no-profile", action="store_true", help="no CPU profile (its sampler costs)")
    ap.add_argument("--out", type=Path, default=None, help="keep the trace's JSON here")
    args = ap.parse_args()
    port = free_port()
    log_path = Path(tempfile.gettempdir()) / f"trace-web-{os.getpid()}.log"
    with open(log_path, "w") as log:
        proc = start_server(port, log)
        driver = None
        try:
            url = wait_url(port, log_path)
            driver = browser()
            driver.get(url)
            size_view(driver)
            time.sleep(1.0)
            # bench_web's probe: the probe vertex's pixel, read by the page's picture worker
            probe = driver.execute_async_script(REPORT_JS)["probe"]["px"]
            driver.execute_script("window.phongPictures.probe = arguments[0];", probe)
            for i in range(2):  # warm-up changes
                driver.execute_async_script(SAMPLE_JS, 300 + 400 * (i % 2))
                time.sleep(0.3)
            addr = driver.capabilities["goog:chromeOptions"]["debuggerAddress"]
            cdp = Cdp(addr)
            page = next(
                t for t in cdp.call("Target.getTargets")["targetInfos"] if t["type"] == "page"
            )
            sess = cdp.call(
                "Target.attachToTarget", {"targetId": page["targetId"], "flatten": True}
            )["sessionId"]
            cdp.call("Network.enable", session=sess)
            cdp.call("Profiler.enable", session=sess)
            cdp.call("Profiler.setSamplingInterval", {"interval": 200}, session=sess)
            driver.execute_script(OBSERVE_JS)
            pids = descendants(driver.service.process.pid)
            cdp.call(
                "Tracing.start",
                {"traceConfig": {"includedCategories": CATEGORIES}, "transferMode": "ReportEvents"},
            )
            if not args.no_profile:
                cdp.call("Profiler.start", session=sess)
            time.sleep(0.5)
            cdp.take("Network.webSocketFrameReceived")
            driver.execute_script("window.muts = [];")
            load0 = os.getloadavg()
            t0, c0 = time.perf_counter(), thread_ticks(pids)
            muts, keys_per = [], []
            for i in range(args.repeat):
                got = driver.execute_async_script(SAMPLE_JS, 300 + 400 * (i % 2))
                if got == -1:
                    raise RuntimeError("no new picture within 20 s")
                time.sleep(0.3)  # the still picture, as bench_web's samples
                muts.append(
                    driver.execute_script("const m = window.muts; window.muts = []; return m;")
                )
                keys_per.append(wire_keys(cdp.take("Network.webSocketFrameReceived")))
            c1, t1 = thread_ticks(pids), time.perf_counter()
            load1 = os.getloadavg()
            prof = None if args.no_profile else cdp.call("Profiler.stop", session=sess)["profile"]
            cdp.call("Tracing.end")
            end = time.monotonic() + 300
            while not cdp.take("Tracing.tracingComplete") and time.monotonic() < end:
                time.sleep(0.1)
            events = [ev for m in cdp.take("Tracing.dataCollected") for ev in m["params"]["value"]]
        finally:
            if driver is not None:
                driver.quit()
            stop(proc)
    n = args.repeat
    print(
        f"# {n} kd changes (bench_web's SAMPLE_JS, 0.3 s still after each), {t1 - t0:.1f} s; "
        f"load {load0[0]:.1f} -> {load1[0]:.1f}"
    )
    print("\n## CPU per change, per process and thread (/proc, ms; includes the tracing's cost)")
    diff = {k: (c1[k] - c0.get(k, 0)) / n for k in c1}
    by_proc = collections.Counter()
    for (kind, _comm), ms in diff.items():
        by_proc[kind] += ms
    for kind, ms in by_proc.most_common():
        print(f"{kind:40s} {ms:7.1f}")
        for (k, comm), v in sorted(diff.items(), key=lambda kv: -kv[1]):
            if k == kind and v >= 0.5:
                print(f"    {comm:36s} {v:7.1f}")
    label, sums = trace_kinds(events)
    print("\n## trace: thread ms per change of the outermost events of each name (top 25 a thread)")
    for key in sorted(sums, key=lambda k: -sum(sums[k].values())):
        total = sums[key]
        if sum(total.values()) / n < 1.0:
            continue
        print(f"### {label[key]}")
        for name, ms in total.most_common(25):
            if ms / n >= 0.2:
                print(f"    {name:50s} {ms / n:7.2f}")
    print("\n## page script: self ms per change (CPU profile, top 30)")
    for ms, where in profile_self(prof, 30) if prof else []:
        print(f"    {ms / n:7.2f}  {where}")
    print("\n## state keys the server sent back, per change")
    for i, ks in enumerate(keys_per):
        print(f"    change {i}: {len(ks)} messages: {ks}")
    print("\n## DOM mutations per change (by nearest aria-label)")
    for i, m in enumerate(muts):
        c = collections.Counter(m)
        print(f"    change {i}: {len(m)}: {dict(c.most_common())}")
    if args.out:
        args.out.write_text(json.dumps({"traceEvents": events}))
    log_path.unlink()


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    main()
