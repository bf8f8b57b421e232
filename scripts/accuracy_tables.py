#!/usr/bin/env python3
"""The tables of scripts/accuracy.sh.

  accuracy_tables.py coverage EXPORT_DIR   JSON: the share of dense poses whose position error
      (against ground_truth.tum, both in the map frame, tied at the first pose) lies within the
      pose's predicted 95 % bound (trajectory.csv's bound95_m); 0.95 is a consistent prediction
  accuracy_tables.py tables OUT_DIR        out/accuracy/tables.md and tables.json from runs/*.json
"""
import bisect
import datetime
import glob
import json
import math
import os
import sys


def coverage(export_dir):
    gt_t, gt_xy = [], []
    with open(os.path.join(export_dir, "ground_truth.tum")) as f:
        for line in f:
            if not line.startswith("#"):
                v = line.split()
                gt_t.append(float(v[0]))
                gt_xy.append((float(v[1]), float(v[2])))
    inside = total = 0
    with open(os.path.join(export_dir, "trajectory.csv")) as f:
        header = f.readline().strip().split(",")
        col = {name: i for i, name in enumerate(header)}
        for line in f:
            v = line.strip().split(",")
            t = float(v[col["time_s"]])
            i = bisect.bisect_left(gt_t, t)
            if i == 0 or i >= len(gt_t):
                continue
            a, b = gt_t[i - 1], gt_t[i]
            if b - a > 0.05:
                continue
            s = (t - a) / (b - a)
            gx = gt_xy[i - 1][0] + s * (gt_xy[i][0] - gt_xy[i - 1][0])
            gy = gt_xy[i - 1][1] + s * (gt_xy[i][1] - gt_xy[i - 1][1])
            err = math.hypot(float(v[col["x_m"]]) - gx, float(v[col["y_m"]]) - gy)
            total += 1
            inside += err <= float(v[col["bound95_m"]])
    print(json.dumps({"bound95_coverage": inside / total if total else None, "bound95_poses": total}))


def fmt(v, scale=1.0, digits=1):
    return "n/a" if v is None else f"{v * scale:.{digits}f}"


def tables(out):
    runs = []
    for path in sorted(glob.glob(os.path.join(out, "runs", "*.json"))):
        with open(path) as f:
            runs.append(json.load(f))
    by = {}
    for r in runs:
        by.setdefault((r["route"], r["profile"], r["seed"]), {})[r["part"]] = r
    date = datetime.date.today().isoformat()
    lines = [f"Made by `scripts/accuracy.sh` on {date} ({len(runs)} runs, offline).", "",
             "Table 2 layout: trajectory errors against the simulator's ground truth (CARMEN logs: "
             "against their reference poses), tied at the first pose; position in mm, heading in "
             "degrees; coverage: dense poses within their predicted 95 % bound.", "",
             "| route | profile | seed | frontend: pos RMSE | SD | max | hdg RMSE | SD | max "
             "| full graph: pos RMSE | SD | max | hdg RMSE | SD | max | loop closures (false) "
             "| 95 % bound coverage |", "|" + "---|" * 17]
    for (route, profile, seed), parts in sorted(by.items()):
        row = [route, profile, str(seed)]
        for part in ("frontend", "graph"):
            r = parts.get(part, {})
            row += [fmt(r.get("position_rmse_m"), 1000), fmt(r.get("position_sd_m"), 1000),
                    fmt(r.get("position_max_m"), 1000), fmt(r.get("heading_rmse_deg"), 1, 3),
                    fmt(r.get("heading_sd_deg"), 1, 3), fmt(r.get("heading_max_deg"), 1, 3)]
        g = parts.get("graph", {})
        row.append(f"{g.get('loop_closures', 'n/a')} ({g.get('false_loop_closures', 'n/a')})")
        row.append(fmt(g.get("bound95_coverage"), 100, 1) + (" %" if g.get("bound95_coverage") is not None else ""))
        lines.append("| " + " | ".join(row) + " |")
    lines += ["", "Table 3 layout: the full graph's cloud against the true surfaces (mm).", "",
              "| route | profile | seed | points | mode | mean | RMSE | 95th percentile | pillar RMSE |",
              "|" + "---|" * 9]
    for (route, profile, seed), parts in sorted(by.items()):
        g = parts.get("graph", {})
        if "cloud_points" not in g:
            continue  # no profile scanner (a CARMEN log)
        lines.append("| " + " | ".join([route, profile, str(seed), str(g.get("cloud_points", "n/a")),
                                         fmt(g.get("cloud_mode_m"), 1000), fmt(g.get("cloud_mean_m"), 1000),
                                         fmt(g.get("cloud_rmse_m"), 1000), fmt(g.get("cloud_p95_m"), 1000),
                                         fmt(g.get("pillar_rmse_m"), 1000)]) + " |")
    relations = os.path.join(out, "runs", "relations.md")
    if os.path.exists(relations):
        with open(relations) as f:
            lines += ["", "The relations benchmark (Kümmerle et al. 2009; translational error mean ± SD "
                      "in m, rotational in degrees):", "", f.read().strip()]
    text = "\n".join(lines) + "\n"
    with open(os.path.join(out, "tables.md"), "w") as f:
        f.write(text)
    with open(os.path.join(out, "tables.json"), "w") as f:
        json.dump({"date": date, "runs": runs}, f, indent=1)
    print(text)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "coverage":
        coverage(sys.argv[2])
    elif len(sys.argv) == 3 and sys.argv[1] == "tables":
        tables(sys.argv[2])
    else:
        sys.exit(__doc__)
