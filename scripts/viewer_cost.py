#!/usr/bin/env python3
"""The figures of scripts/viewer-cost.sh, from the runs it left in OUT: per run, every process's
CPU time [s] and the monitor's losses and verdict (OUT/RUN/monitor.json), the browser's figures
(OUT/RUN-page.json), how the live graph kept up with the sensors (OUT/RUN/run.lcmlog: the
frontend's and backend's rates and their lags behind the scans, below) and the machine's load
during the run (OUT/RUN-load.json); then min / median / max per kind of run. JSON last.

Lags [s] are wall-clock times between the recorder's receipt of a scan (SCAN_HORIZONTAL) and of
what the graph made of it, matched by data time: the frontend's pose of that scan
(POSE_FRONTEND), the backend's key poses whose newest is that scan's (KEY_POSES, first part) and
the annotator's colours for them (ANNOTATIONS, first part; what the viewer shows lags by this).

    scripts/viewer_cost.py OUT RUN,RUN,... DURATION_S
"""
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lcmlog  # noqa: E402  (scripts/lcmlog.py)

LAGGED = ("POSE_FRONTEND", "KEY_POSES", "ANNOTATIONS")


def quantiles(xs):
    if not xs:
        return None
    xs = sorted(xs)
    return {"median": round(statistics.median(xs), 4),
            "p95": round(xs[min(len(xs) - 1, int(0.95 * len(xs)))], 4), "max": round(xs[-1], 4)}


def keeping_up(path, types):
    """Rates [Hz] and lags [s] of the frontend and backend from a recorded run."""
    scan_at = {}  # data time (utime and utime_last of each scan) -> event time [us]
    counts = {c: 0 for c in ("SCAN_HORIZONTAL",) + LAGGED}
    span = {}
    lags = {c: [] for c in LAGGED}
    unmatched = {c: 0 for c in LAGGED}
    seen = set()
    for _offset, ts, channel, data in lcmlog.events(path, channels=set(counts)):
        if data is None:
            continue
        msg = lcmlog.decode(types, data)
        if msg is None:
            continue
        counts[channel] += 1
        first, _ = span.get(channel, (ts, ts))
        span[channel] = (first, ts)
        if channel == "SCAN_HORIZONTAL":
            scan_at.setdefault(msg.utime, ts)
            scan_at.setdefault(msg.utime_last, ts)
            continue
        if (channel, msg.utime) in seen:  # later parts of one update
            continue
        seen.add((channel, msg.utime))
        at = scan_at.get(msg.utime)
        if at is None:
            unmatched[channel] += 1
        else:
            lags[channel].append((ts - at) * 1e-6)
    rate = lambda c: (round(counts[c] / ((span[c][1] - span[c][0]) * 1e-6), 2)
                      if c in span and span[c][1] > span[c][0] else None)
    return {
        "scans": counts["SCAN_HORIZONTAL"], "frontend_poses": counts["POSE_FRONTEND"],
        "scan_hz": rate("SCAN_HORIZONTAL"), "frontend_hz": rate("POSE_FRONTEND"),
        "frontend_poses_per_scan": round(counts["POSE_FRONTEND"] / max(counts["SCAN_HORIZONTAL"], 1), 4),
        "backend_updates": len([1 for (c, _) in seen if c == "KEY_POSES"]),
        "frontend_lag_s": quantiles(lags["POSE_FRONTEND"]),
        "backend_lag_s": quantiles(lags["KEY_POSES"]),
        "annotator_lag_s": quantiles(lags["ANNOTATIONS"]),
        "unmatched": unmatched,
    }


def row_of(out, run, types):
    try:
        mon = json.load(open(os.path.join(out, run, "monitor.json")))
    except (OSError, ValueError):
        return None
    procs = mon.get("processes", {})
    cpu = {name: round(p.get("cpu_s") or 0.0, 2) for name, p in procs.items()}
    lost = {k: sum(p.get(k) or 0 for n, p in procs.items() if n != "monitor")
            for k in ("missed", "queue_dropped", "out_of_order", "rejected", "decode_failures")}
    graph = [n for n in procs if n not in ("monitor", "viewer")]
    row = {"cpu_s": cpu, "graph_cpu_s": round(sum(cpu[n] for n in graph), 2),
           "max_status_gap_s": round(max((p.get("max_status_gap_s") or 0.0) for p in procs.values()), 2),
           "problems": mon.get("problems", []), **lost}
    page = os.path.join(out, run + "-page.json")
    if os.path.exists(page):
        try:
            row["page"] = json.loads(open(page).read().strip().splitlines()[-1]).get("watched")
        except (ValueError, IndexError):
            row["page"] = None
    load = os.path.join(out, run + "-load.json")
    if os.path.exists(load):
        row["machine"] = json.load(open(load))
    log = os.path.join(out, run, "run.lcmlog")
    if os.path.exists(log):
        row["keeping_up"] = keeping_up(log, types)
    return row


def main(out, runs, duration):
    types = lcmlog.message_types()
    result = {"duration_s": duration, "runs": {}}
    for run in runs:
        row = result["runs"][run] = row_of(out, run, types)
        if not row:
            continue
        k, m = row.get("keeping_up", {}), row.get("machine", {})
        lag = lambda key: (k.get(key) or {}).get("median")
        print(f"{run:10s} graph CPU {row['graph_cpu_s']:7.2f} s (viewer {row['cpu_s'].get('viewer', 0):.2f} s); "
              f"missed {row['missed']}, dropped {row['queue_dropped']}, rejected {row['rejected']}; "
              f"frontend {k.get('frontend_poses_per_scan')} poses/scan, lag median {lag('frontend_lag_s')} s, "
              f"backend lag {lag('backend_lag_s')} s; load {m.get('load_1min_start')}-{m.get('load_1min_end')}, "
              f"machine busy {m.get('busy_share')}; verdict problems {len(row['problems'])}", file=sys.stderr)
    kinds = {}
    for run, row in result["runs"].items():
        if row:
            kinds.setdefault(run.rsplit("-", 1)[0] if run[-1].isdigit() else run, []).append(row)
    result["kinds"] = {}
    spread = lambda xs: [min(xs), statistics.median(xs), max(xs)] if xs else None
    for kind, rows in kinds.items():
        lags = lambda key: [r["keeping_up"][key]["median"] for r in rows
                            if r.get("keeping_up", {}).get(key)]
        result["kinds"][kind] = k = {
            "runs": len(rows),
            "graph_cpu_s": spread([r["graph_cpu_s"] for r in rows]),
            "viewer_cpu_s": spread([r["cpu_s"].get("viewer", 0.0) for r in rows]),
            "mapper_cpu_s": spread([r["cpu_s"].get("mapper", 0.0) for r in rows]),
            "chromium_cpu_s": spread([(r.get("page") or {}).get("chromium_cpu_s", 0.0) for r in rows]),
            "missed": spread([r["missed"] for r in rows]),
            "frontend_poses_per_scan": spread([r["keeping_up"]["frontend_poses_per_scan"]
                                               for r in rows if "keeping_up" in r]),
            "frontend_lag_median_s": spread(lags("frontend_lag_s")),
            "backend_lag_median_s": spread(lags("backend_lag_s")),
            "annotator_lag_median_s": spread(lags("annotator_lag_s")),
            "load_1min": spread([v for r in rows for v in (r.get("machine", {}).get("load_1min_start"),
                                                           r.get("machine", {}).get("load_1min_end"))
                                 if v is not None]),
            "runs_with_problems": sum(1 for r in rows if r["problems"]),
        }
        print(f"{kind:8s} x{len(rows)}: graph CPU {k['graph_cpu_s']} s, viewer {k['viewer_cpu_s']} s, "
              f"chromium {k['chromium_cpu_s']} s, missed {k['missed']}, frontend lag "
              f"{k['frontend_lag_median_s']} s, backend lag {k['backend_lag_median_s']} s, load "
              f"{k['load_1min']}, runs with verdict problems {k['runs_with_problems']}", file=sys.stderr)
    print(json.dumps(result))


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2].split(","), float(sys.argv[3]))
