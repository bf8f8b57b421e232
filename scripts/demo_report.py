#!/usr/bin/env python3
"""The demo's report: merges the evaluation (eval.json), the export (export.json) and the monitor's
verdict (monitor.json) of a demo folder into report.json, draws trajectory.png (the estimate over
the ground truth or reference, top view), writes report.md, and prints a short summary with the
path and size of every product.
Usage: demo_report.py --out DIR --what TEXT --seconds S"""
import argparse
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PRODUCTS = [  # (file, what)
    ("trajectory.tum", "dense trajectory, TUM format (evo reads it)"),
    ("trajectory.csv", "dense trajectory with covariance, 95 % bound and level per pose"),
    ("ground_truth.tum", "simulator ground truth, TUM format"),
    ("reference.tum", "the CARMEN log's reference poses (another SLAM system's), TUM format"),
    ("cloud.ply", "point cloud, PLY (accuracy colour, level)"),
    ("cloud.las", "point cloud, LAS 1.4 (GPS time, intensity, accuracy colour, level)"),
    ("map.bt", "OctoMap, binary (map frame, whatever --frame says: a voxel grid does not turn)"),
    ("map.ot", "OctoMap, full (map frame)"),
    ("map_colour.ot", "OctoMap, voxels in the accuracy colour of the worst level of their points"),
    ("report.md", "accuracy report, Markdown"),
    ("report.json", "accuracy report, every figure"),
    ("trajectory.png", "trajectory plot"),
    ("errors.png", "error plot over time"),
    ("run.lcmlog", "the recorded run (every message; scripts/examples/read_run_log.py)"),
    ("monitor.json", "the monitor's verdict and per-process figures"),
    ("logs", "every process's output, the evaluation's and the export's JSON, errors.csv"),
]


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def read_tum(path):
    xs, ys = [], []
    try:
        with open(path) as f:
            for line in f:
                if line.startswith("#"):
                    continue
                v = line.split()
                xs.append(float(v[1]))
                ys.append(float(v[2]))
    except OSError:
        pass
    return xs, ys


def size_text(n):
    for unit in ("bytes", "kB", "MB", "GB"):
        if n < 1000 or unit == "GB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1000.0
    return f"{n:.1f} GB"


def mm(v):
    return "n/a" if v is None else f"{1000 * v:.1f} mm"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--what", required=True)
    ap.add_argument("--seconds", type=float, required=True)
    ap.add_argument("--removed", action="append", default=[],
                    help="what the run made and did not keep, and why (said in the summary)")
    a = ap.parse_args()
    out = a.out
    ev, ex = load(f"{out}/logs/eval.json"), load(f"{out}/logs/export.json")
    mon = load(f"{out}/monitor.json")
    frame = ex.get("frame", "map")

    # The plot: estimate over the reference, both in the products' frame.
    est = read_tum(f"{out}/trajectory.tum")
    ref_file = "ground_truth" if os.path.exists(f"{out}/ground_truth.tum") else "reference"
    ref = read_tum(f"{out}/{ref_file}.tum")
    fig, ax = plt.subplots(figsize=(9, 5))
    if ref[0]:
        ax.plot(ref[0], ref[1], color="0.6", lw=2.5, label=ref_file.replace("_", " "))
    ax.plot(est[0], est[1], color="tab:blue", lw=1, label="Traverse (final dense trajectory)")
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [m], frame {frame}")
    ax.set_ylabel(f"y [m], frame {frame}")
    ax.legend(loc="best")
    ax.set_title(a.what)
    fig.tight_layout()
    fig.savefig(f"{out}/trajectory.png", dpi=110)

    duration = ev.get("duration_s")
    headline = [
        ("input", a.what),
        ("data", f"{duration:.1f} s, {ev.get('length_m', 0):.1f} m travelled" if duration else "n/a"),
        ("trajectory position error, RMSE / max", f"{mm(ev.get('position_rmse_m'))} / {mm(ev.get('position_max_m'))}"),
        ("heading error, RMSE / max", "n/a" if ev.get("heading_rmse_deg") is None else
         f"{ev['heading_rmse_deg']:.3f} deg / {ev['heading_max_deg']:.3f} deg"),
        ("loop closures (false by the reference)", f"{ev.get('loop_closures', 0)} ({ev.get('false_loop_closures', 0)})"),
    ]
    if "cloud_rmse_m" in ev:
        headline.append(("cloud to the true surfaces, RMSE / 95th percentile",
                         f"{mm(ev.get('cloud_rmse_m'))} / {mm(ev.get('cloud_p95_m'))}"))
    if "cloud_points_written" in ex:
        levels = ", ".join(f"{k} {v:,}" for k, v in sorted(ex.get("cloud_points_per_level", {}).items(), reverse=True))
        headline.append(("cloud points written", f"{ex['cloud_points_written']:,} of {ex['cloud_points_read']:,} (one in {ex.get('thin_every')})"))
        headline.append(("points per USIBD level of accuracy (95 % bound)", levels))
    headline.append(("largest key-pose 95 % bound", mm(ex.get("key_pose_bound95_max_m"))))
    headline.append(("monitor verdict", "ok" if mon.get("ok") else "FAILED: " + "; ".join(mon.get("problems", [])) if mon else "n/a"))
    headline.append(("frame of the products", frame + (" (tied to the ground truth at the first pose)" if frame == "world" else " (the base at the first scan)")))
    headline.append(("wall time", f"{a.seconds:.0f} s"))

    files = []
    for name, what in PRODUCTS:
        path = os.path.join(out, name)
        if os.path.exists(path) or name in ("report.md", "report.json"):
            files.append((name, what, path))
    report = {"what": a.what, "wall_s": a.seconds, "frame": frame,
              "frames": {"trajectory": frame, "cloud": frame, "octomap": "map"}, "not_kept": a.removed,
              "evaluation": ev, "export": ex,
              "monitor": {"ok": mon.get("ok"), "problems": mon.get("problems", [])}}
    with open(f"{out}/report.json", "w") as f:
        json.dump(report, f, indent=2)

    with open(f"{out}/report.md", "w") as f:
        f.write(f"# Traverse run: {a.what}\n\n| figure | value |\n|---|---|\n")
        for k, v in headline:
            f.write(f"| {k} | {v} |\n")
        f.write(f"\nErrors against the {ref_file.replace('_', ' ')} after tying the estimate to it at its first pose "
                "(seed 000's Table 2 convention). The 95 % bound is 2 sqrt of the largest eigenvalue "
                "of a key pose's marginal position covariance (seed 004), against the USIBD levels "
                "of accuracy: LOA 50 up to 1 mm, 40 up to 5 mm, 30 up to 15 mm, 20 up to 50 mm.\n\n")
        f.write(f"![trajectory](trajectory.png)\n\n")
        if os.path.exists(f"{out}/errors.png"):
            f.write("![errors over time](errors.png)\n\n")
        f.write("| file | what |\n|---|---|\n")
        for name, what, _ in files:
            f.write(f"| `{name}` | {what} |\n")
        for r in a.removed:
            f.write(f"\nNot kept: {r}.\n")

    print()
    for k, v in headline:
        print(f"  {k}: {v}")
    print(f"\nProducts in {out}/:")
    total = 0
    for name, what, path in files:
        n = (sum(os.path.getsize(os.path.join(path, f)) for f in os.listdir(path))
             if os.path.isdir(path) else os.path.getsize(path))
        total += n
        print(f"  {name + ('/' if os.path.isdir(path) else ''):17} {size_text(n):>9}  {what}")
    print(f"  {'total':17} {size_text(total):>9}")
    for r in a.removed:
        print(f"  not kept: {r}")
    print(f"\nFull figures: {out}/report.json; report with plots: {out}/report.md")


if __name__ == "__main__":
    main()
