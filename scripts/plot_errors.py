#!/usr/bin/env python3
"""Plots the error time series written by traverse-evaluator (errors.csv) in the style of seed
000's Figure 3: position error on top, heading error below, against time; beside them the two
trajectories in the reference frame.

usage: plot_errors.py ERRORS_CSV OUT_PNG [--title TITLE]
Exit codes: 0 written, 2 bad input, 3 matplotlib is not installed (python3-matplotlib).
"""
import argparse
import csv
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv")
    parser.add_argument("png")
    parser.add_argument("--title", default="")
    args = parser.parse_args()
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("plot_errors.py: matplotlib is not installed", file=sys.stderr)
        return 3

    cols = {}
    try:
        with open(args.csv, newline="") as f:
            for row in csv.DictReader(f):
                for key, value in row.items():
                    cols.setdefault(key, []).append(float(value))
    except (OSError, ValueError) as e:
        print(f"plot_errors.py: cannot read {args.csv}: {e}", file=sys.stderr)
        return 2
    if not cols:
        print(f"plot_errors.py: {args.csv} has no rows", file=sys.stderr)
        return 2

    fig = plt.figure(figsize=(12, 6), constrained_layout=True)
    grid = fig.add_gridspec(2, 2, width_ratios=[3, 2])
    ax_pos = fig.add_subplot(grid[0, 0])
    ax_head = fig.add_subplot(grid[1, 0], sharex=ax_pos)
    ax_xy = fig.add_subplot(grid[:, 1])

    # Millimetres as in seed 000's figure, metres once the errors outgrow them.
    in_mm = max(cols["position_error_m"]) < 1.0
    scale, unit = (1000.0, "mm") if in_mm else (1.0, "m")
    ax_pos.plot(cols["time_s"], [scale * e for e in cols["position_error_m"]], lw=0.8)
    ax_pos.set_ylabel(f"position error [{unit}]")
    ax_pos.grid(True, alpha=0.3)
    ax_head.plot(cols["time_s"], cols["heading_error_deg"], lw=0.8, color="tab:orange")
    ax_head.set_ylabel("heading error [deg]")
    ax_head.set_xlabel("time [s]")
    ax_head.grid(True, alpha=0.3)

    ax_xy.plot(cols["ref_x_m"], cols["ref_y_m"], color="tab:red", lw=1.0, label="reference")
    ax_xy.plot(cols["est_x_m"], cols["est_y_m"], color="tab:blue", lw=0.8, label="estimate")
    ax_xy.set_xlabel("x [m]")
    ax_xy.set_ylabel("y [m]")
    ax_xy.set_aspect("equal", adjustable="datalim")
    ax_xy.legend(loc="best")
    ax_xy.grid(True, alpha=0.3)
    if args.title:
        fig.suptitle(args.title)
    fig.savefig(args.png, dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
