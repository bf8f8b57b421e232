#!/usr/bin/env python3
"""scripts/eval-kummerle.sh --all: the relations benchmark on intel, aces and fr079, Traverse's
frontend alone and full graph beside the published figures, as one Markdown table.

Usage (through scripts/eval-kummerle.sh --all): kummerle_table.py EVAL_SCRIPT [--offline]
[--speed S]. Runs EVAL_SCRIPT NAME --stages ... for each log and stage list (one long run at a
time), prints the table on stdout and writes every run's JSON to out/eval/kummerle-all.json.
"""
import argparse
import datetime
import json
import os
import subprocess
import sys

LOGS = ["intel", "aces", "fr079"]
FRONTEND, FULL = "frontend", "frontend,backend,densifier"
# Hess et al. 2016, Table II (mean ± SD of the translational error [m], then of the rotational
# error [deg]; GMapping's rotational error is not given) and Table V (Cartographer's wall-clock
# time [s] for the log's duration [s]).
PUBLISHED = {
    "intel": ("0.0229 ± 0.0239, 0.453 ± 1.335", "0.031 ± 0.026, 1.3 ± 4.7", "0.070 ± 0.083"),
    "aces": ("0.0375 ± 0.0426, 0.373 ± 0.469", "0.044 ± 0.044, 0.4 ± 0.4", "0.060 ± 0.049"),
    "fr079": ("0.0452 ± 0.0354, 0.538 ± 0.718", "0.056 ± 0.042, 0.6 ± 0.6", "0.061 ± 0.044"),
}
CARTOGRAPHER_WALL = {"intel": (179, 2691), "aces": (41, 1366), "fr079": (62, 1061)}
# A relation off by this much [m] or more: the map is broken there (the benchmark's errors are
# centimetres), the run is marked lost.
LOST_M = 1.0


def run(script, name, stages, offline, speed):
    cmd = [script, name, "--stages", stages, "--speed", str(speed)] + (["--offline"] if offline else [])
    print(f"kummerle: {' '.join(cmd)}", file=sys.stderr, flush=True)
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines = [l for l in p.stdout.splitlines() if l.startswith("{")]
    result = json.loads(lines[-1]) if lines else {}
    result["exit_code"] = p.returncode
    if p.returncode != 0:
        errors = [l for l in p.stderr.splitlines() if l.strip()]
        result["failure"] = errors[-1] if errors else f"exit {p.returncode}"
    return result


def cell(r):
    if "relations" not in r:
        return "failed: " + r.get("failure", "no result")
    used = f"{r['relations_used']} of {r['relations']} relations"
    if r.get("refused"):
        return f"refused: {used}"
    text = (f"{r['trans_mean_m']:.4f} ± {r['trans_sd_m']:.4f}, "
            f"{r['rot_mean_deg']:.3f} ± {r['rot_sd_deg']:.3f} ({used})")
    if r["trans_max_m"] >= LOST_M:
        text += f", lost (largest {r['trans_max_m']:.2f} m)"
    return text


def wall(r):
    return f"{r['wall_s']:.0f} s" if r.get("wall_s") is not None else "-"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("script")
    ap.add_argument("--offline", action="store_true")
    ap.add_argument("--speed", default="1")
    a = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    results = {name: {s: run(a.script, name, s, a.offline, a.speed) for s in (FRONTEND, FULL)}
               for name in LOGS}

    mode = "offline" if a.offline else f"live at {a.speed}x"
    print(f"Relations benchmark, {datetime.date.today().isoformat()}, Traverse {mode}: mean ± SD "
          "of the translational error [m], then of the rotational error [deg], over the "
          "relations used (Kümmerle et al. 2009); published figures from Hess et al. 2016, "
          "Tables II and V. Wall-clock: time to process the log, against its duration.\n")
    print("| log | Cartographer | Graph Mapping (Kümmerle 2009) | GMapping | Traverse frontend "
          "alone | Traverse full graph (frontend, backend, densifier) | wall-clock: Cartographer "
          "/ Traverse frontend / full graph |")
    print("|---|---|---|---|---|---|---|")
    for name in LOGS:
        fe, full = results[name][FRONTEND], results[name][FULL]
        c_wall, c_log = CARTOGRAPHER_WALL[name]
        log_s = fe.get("log_s") or full.get("log_s") or c_log
        print(f"| {name} | {' | '.join(PUBLISHED[name])} | {cell(fe)} | {cell(full)} | "
              f"{log_s:.0f} s of data: {c_wall} s / {wall(fe)} / {wall(full)} |")
    out = os.path.join(root, "out", "eval", "kummerle-all.json")
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with open(out, "w") as f:
        json.dump(results, f, indent=1)
    print(f"kummerle: every run's JSON in {out}", file=sys.stderr)
    failed = [f"{n} {s}" for n in LOGS for s in (FRONTEND, FULL) if results[n][s]["exit_code"]]
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
