#!/usr/bin/env python3
"""The tables of scripts/accuracy.sh.

  accuracy_tables.py coverage EXPORT_DIR   JSON: the share of dense poses whose position error
      (against ground_truth.tum, both in the map frame, tied at the first pose) lies within the
      pose's predicted 95 % bound (trajectory.csv's bound95_m); 0.95 is a consistent prediction
  accuracy_tables.py tables OUT_DIR COMMAND  out/accuracy/tables.md and tables.json from
      runs/*.json, saying which COMMAND made them
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


def row_key(r):
    """(input, profile, seed, set) of a run: a simulated route, or a CARMEN log (real data)."""
    name = r.get("route") or f"carmen-{r.get('carmen', '?')}"
    return name, r.get("profile", "real"), r.get("seed", "n/a"), r.get("set", "default")


def trajectory_cells(r):
    """Position RMSE, SD, max [mm]; heading RMSE, SD, max [deg]."""
    return [fmt(r.get("position_rmse_m"), 1000), fmt(r.get("position_sd_m"), 1000),
            fmt(r.get("position_max_m"), 1000), fmt(r.get("heading_rmse_deg"), 1, 3),
            fmt(r.get("heading_sd_deg"), 1, 3), fmt(r.get("heading_max_deg"), 1, 3)]


def tables(out, command):
    runs = []
    for path in sorted(glob.glob(os.path.join(out, "runs", "*.json"))):
        with open(path) as f:
            runs.append(json.load(f))
    runs.sort(key=lambda r: tuple(str(k) for k in row_key(r)))
    dates = sorted({r["date"] for r in runs if r.get("date")}) or [datetime.date.today().isoformat()]
    made = dates[0] if len(dates) == 1 else f"{dates[0]} to {dates[-1]}"
    durations = sorted({r.get("sim_duration_s") for r in runs if r.get("route")}, key=str)
    span = ("the first " + " / ".join(f"{d:g} s" for d in durations if d) + " of every route"
            if any(durations) else "whole routes")
    lines = [f"Made by `{command}` ({made}; {len(runs)} runs, offline, {span}; "
             f"{sum(r.get('wall_s', 0) for r in runs) / 3600:.1f} h of runs).", "",
             "Table 2 layout: trajectory errors against the simulator's ground truth (CARMEN logs: "
             "against their reference poses, another system's estimate), tied at the first pose; "
             "position in mm, heading in degrees; loop closures (false ones by the reference); "
             "coverage: the share of dense poses whose error lies within their predicted 95 % bound "
             "(95 % is consistent). Parameter sets: configs/accuracy.yaml.", "",
             "| input | profile | seed | set | frontend: pos RMSE [mm] | SD [mm] | max [mm] "
             "| hdg RMSE [deg] | SD [deg] | max [deg] | full graph: pos RMSE [mm] | SD [mm] "
             "| max [mm] | hdg RMSE [deg] | SD [deg] | max [deg] | loop closures (false) "
             "| 95 % bound coverage [%] | run wall-clock [s] |", "|" + "---|" * 19]
    for r in runs:
        row = [str(k) for k in row_key(r)]
        row += trajectory_cells(r.get("frontend", {})) + trajectory_cells(r)
        row.append(f"{r.get('loop_closures', 'n/a')} ({r.get('false_loop_closures', 'n/a')})")
        row.append(fmt(r.get("bound95_coverage"), 100, 1))
        row.append(str(r.get("wall_s", "n/a")))
        lines.append("| " + " | ".join(row) + " |")
    lines += ["", "Table 3 layout: the full graph's cloud against the true surfaces of the "
              "simulated world (distance of each point to the nearest surface, mm; pillar RMSE: "
              "the pillars' fitted centres against the true ones).", "",
              "| route | profile | seed | set | points | mode [mm] | mean [mm] | RMSE [mm] "
              "| 95th percentile [mm] | pillar RMSE [mm] |", "|" + "---|" * 10]
    for r in runs:
        if "cloud_points" not in r:
            continue  # no profile scanner (a CARMEN log)
        lines.append("| " + " | ".join([str(k) for k in row_key(r)] + [
            f"{r['cloud_points']:,}", fmt(r.get("cloud_mode_m"), 1000), fmt(r.get("cloud_mean_m"), 1000),
            fmt(r.get("cloud_rmse_m"), 1000), fmt(r.get("cloud_p95_m"), 1000),
            fmt(r.get("pillar_rmse_m"), 1000)]) + " |")
    relations = os.path.join(out, "runs", "relations.md")
    if os.path.exists(relations):
        with open(relations) as f:
            lines += ["", "The relations benchmark (Kümmerle et al. 2009, shipped configs; "
                      "translational error mean ± SD in m, rotational in degrees):", "",
                      f.read().strip()]
    text = "\n".join(lines) + "\n"
    with open(os.path.join(out, "tables.md"), "w") as f:
        f.write(text)
    with open(os.path.join(out, "tables.json"), "w") as f:
        json.dump({"command": command, "dates": dates, "runs": runs}, f, indent=1)
    print(text)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "coverage":
        coverage(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "tables":
        tables(sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)
