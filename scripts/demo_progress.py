#!/usr/bin/env python3
"""Progress of a demo run, read from the files the run is writing (scripts/demo.sh starts it):
which stage works, how many seconds of data it has done out of how many, and at what rate
(seconds of data per second of wall time). The stages' files:
  out/cache/INPUT*.lcmlog.tmp      the simulator (or the CARMEN driver) writing the input log
                                   (--input INPUT: the start of its name, so that another run
                                   simulating into the same folder is not taken for this one)
  OUT/<stage>.lcmlog               an offline stage's record (each event stamped with data time)
  OUT/run.lcmlog                   the live graph's recording: the frontend's newest pose time
                                   against its first (the first scan's; the sensor channels may
                                   not be recorded, --no-run-log)
Usage: demo_progress.py --watch PID --out OUT --cache DIR [--input INPUT] [--total S] [--log FILE]
Prints a line every few seconds until process PID ends; --log FILE: the run's own output, where
the simulator's summary line gives the total when --total is not known."""
import argparse
import glob
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lcmlog  # noqa: E402


class Watched:
    """A log being written: where reading resumes, its first and newest data times [us]."""

    def __init__(self, path, stage, live):
        self.path, self.stage, self.live = path, stage, live
        self.offset, self.first, self.newest = 0, None, None
        self.key_poses = self.closures = None
        self.started = time.monotonic()
        self.types = lcmlog.message_types() if live else None

    def update(self):
        wanted = {"POSE_FRONTEND", "KEY_POSES"} if self.live else None
        try:
            for offset, utime, channel, data in lcmlog.events(self.path, self.offset, wanted):
                self.offset = offset
                if self.live:
                    if data is None:
                        continue
                    msg = lcmlog.decode(self.types, data)
                    if msg is None:
                        continue
                    if channel == "POSE_FRONTEND":
                        # The first pose is the first scan's: the span of data the graph has done.
                        self.first = msg.utime if self.first is None else self.first
                        self.newest = msg.utime
                    if channel == "KEY_POSES":
                        self.key_poses, self.closures = msg.total_key_poses, msg.total_loop_closures
                else:
                    if self.first is None:
                        self.first = utime
                    self.newest = utime
        except (OSError, ValueError):
            pass

    def done_s(self):
        if self.first is None or self.newest is None:
            return 0.0
        return max(0.0, (self.newest - self.first) * 1e-6)


def total_from_log(path):
    """The simulator's sim_duration_s, from its JSON line in the run's output (None until then)."""
    try:
        with open(path) as f:
            for line in f:
                if not line.startswith("{"):
                    continue
                try:
                    value = json.loads(line).get("sim_duration_s")
                except ValueError:
                    continue
                if value is not None:
                    return value
    except OSError:
        pass
    return None


def newest_file(out, cache, prefix):
    candidates = (glob.glob(os.path.join(cache, glob.escape(prefix) + "*.lcmlog.tmp"))
                  + glob.glob(os.path.join(out, "*.lcmlog")))
    candidates = [c for c in candidates if os.path.exists(c)]
    return max(candidates, key=os.path.getmtime) if candidates else None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--watch", type=int, required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--cache", required=True)
    ap.add_argument("--input", default="", help="the start of the input log's name in --cache")
    ap.add_argument("--total", type=float)
    ap.add_argument("--log")
    ap.add_argument("--every", type=float, default=10.0)
    ap.add_argument("--input-stage", default="simulate", help="name of the stage writing the input log")
    a = ap.parse_args()
    start = time.monotonic()
    watched = {}
    last_print = 0.0
    while True:
        alive = os.path.exists(f"/proc/{a.watch}")
        path = newest_file(a.out, a.cache, a.input)
        if path and path not in watched and os.path.getmtime(path) >= time.time() - 60:
            name = os.path.basename(path)
            if name.endswith(".tmp"):
                stage, live = a.input_stage, False
            elif name == "run.lcmlog":
                stage, live = "graph (live)", True
            else:
                stage, live = name[: -len(".lcmlog")], False
            if not (stage == "graph (live)" and any(not w.live and w.stage != a.input_stage for w in watched.values())):
                watched[path] = Watched(path, stage, live)
        now = time.monotonic()
        after = [f for f in ("cloud-eval.out", "evaluator.out")
                 if os.path.exists(os.path.join(a.out, f))
                 and os.path.getmtime(os.path.join(a.out, f)) >= time.time() - (now - start)]
        if after and (now - last_print >= a.every or not alive):
            stage = "cloud evaluation" if after[0] == "cloud-eval.out" else "trajectory evaluation"
            print(f"  [{now - start:5.0f} s] {stage}", flush=True)
            last_print = now
        elif watched and (now - last_print >= a.every or not alive):
            w = max(watched.values(), key=lambda x: x.started)
            w.update()
            total = a.total or (total_from_log(a.log) if a.log else None)
            done = w.done_s()
            elapsed = now - w.started
            rate = f", {done / elapsed:5.2f} s of data per s" if elapsed >= 2 else ""
            part = f"{done:6.1f} s of {total:.1f} s of data ({100 * done / total:3.0f} %)" if total else f"{done:6.1f} s of data"
            graph = f", {w.key_poses} key poses, {w.closures} loop closures" if w.key_poses is not None else ""
            print(f"  [{now - start:5.0f} s] {w.stage:14} {part}{rate}{graph}", flush=True)
            last_print = now
        if not alive:
            return
        time.sleep(0.5)


if __name__ == "__main__":
    main()
