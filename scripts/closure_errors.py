#!/usr/bin/env python3
"""Each loop closure's error against the simulator's truth, beside what could explain it.

    scripts/closure_errors.py RUN_DIR [--clock-offset-ms MS --clock-drift-ppm PPM] [--json-only]

RUN_DIR is an eval-route.sh output folder of a run with the backend (closures.csv, written by
traverse-evaluator, and run.lcmlog with POSE_GROUND_TRUTH). Per closure it prints the heading
error the evaluator found [deg], the true heading change between the two key poses [deg], the
true turn rate of the cart at either key pose [deg/s] (from the ground truth over +-50 ms) and
the heading error that a stamp off by dt at either pose would show by itself,
omega_to * dt_to - omega_from * dt_from [deg]. The last line is JSON: mean, SD and largest
|heading error|, and of the closures flagged false by the evaluator.

The clock options are for runs whose truth is in true time (simulated before 2026-11-27; since
then traverse-sim stamps its truth by the horizontal scanner's clock and dt is zero): with that
scanner's clock (traverse-sim prints it in its JSON line, `true_clocks.laser_horizontal`: stamp =
true time + offset + drift x time since the start), dt is known, and each error is also given
against the truth at the scans' true times, with the correlation of the errors with the stamp
term. How issue 20's closure heading bias was traced to the truth's time base (processes/sim/
README.md, "Clocks").
"""
import argparse
import bisect
import csv
import json
import math
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lcmlog  # noqa: E402  (scripts/lcmlog.py)


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


class Truth:
    """POSE_GROUND_TRUTH (true time), interpolated linearly (heading on the short arc)."""

    def __init__(self, log_path):
        types = lcmlog.message_types()
        self.t, self.x, self.y, self.th = [], [], [], []
        for _off, _utime, _ch, data in lcmlog.events(log_path, channels={"POSE_GROUND_TRUTH"}):
            if data is None:
                continue
            m = lcmlog.decode(types, data)
            if m is None or (self.t and m.utime <= self.t[-1]):
                continue
            self.t.append(m.utime)
            self.x.append(m.x)
            self.y.append(m.y)
            self.th.append(m.theta)
        if len(self.t) < 2:
            raise SystemExit(f"closure_errors: no POSE_GROUND_TRUTH in {log_path}")

    def at(self, utime):
        i = min(max(bisect.bisect_right(self.t, utime) - 1, 0), len(self.t) - 2)
        f = (utime - self.t[i]) / (self.t[i + 1] - self.t[i])
        f = min(max(f, 0.0), 1.0)
        th = self.th[i] + f * wrap(self.th[i + 1] - self.th[i])
        return (self.x[i] + f * (self.x[i + 1] - self.x[i]),
                self.y[i] + f * (self.y[i + 1] - self.y[i]), wrap(th))

    def rate(self, utime, half_us=50000):
        """[rad/s] heading rate about utime."""
        a, b = self.at(utime - half_us), self.at(utime + half_us)
        return wrap(b[2] - a[2]) / (2e-6 * half_us)


def between(a, b):
    """b in a's frame."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    c, s = math.cos(a[2]), math.sin(a[2])
    return (c * dx + s * dy, -s * dx + c * dy, wrap(b[2] - a[2]))


def spread(values):
    if not values:
        return None
    return {"mean": round(statistics.fmean(values), 4),
            "sd": round(statistics.pstdev(values), 4),
            "max_abs": round(max(abs(v) for v in values), 4)}


def correlation(a, b):
    if len(a) < 3 or statistics.pstdev(a) == 0 or statistics.pstdev(b) == 0:
        return None
    return round(statistics.correlation(a, b), 3)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--clock-offset-ms", type=float, help="horizontal scanner clock offset [ms]")
    ap.add_argument("--clock-drift-ppm", type=float, help="horizontal scanner clock drift [ppm]")
    ap.add_argument("--json-only", action="store_true", help="print only the JSON line")
    args = ap.parse_args()
    clock = None
    if (args.clock_offset_ms is None) != (args.clock_drift_ppm is None):
        ap.error("give both --clock-offset-ms and --clock-drift-ppm, or neither")
    if args.clock_offset_ms is not None:
        clock = (1e-3 * args.clock_offset_ms, 1e-6 * args.clock_drift_ppm)

    with open(os.path.join(args.run_dir, "closures.csv")) as f:
        rows = [r for r in csv.DictReader(f) if r["matched"] == "1"]
    truth = Truth(os.path.join(args.run_dir, "run.lcmlog"))
    start = truth.t[0]  # the simulator's first ground-truth sample is the route's start

    def true_time(stamp):
        # stamp = true + offset + drift (true - start), so true = start + (stamp - start - offset)
        # / (1 + drift).
        off, drift = clock
        return start + round((stamp - start - 1e6 * off) / (1.0 + drift))

    err_before, err_after, stamp_term, flagged = [], [], [], []
    if not args.json_only:
        print(f"{'from':>5} {'to':>5} {'t_to [s]':>8} {'dhdg [deg]':>10} {'w_from':>7} {'w_to':>7} "
              f"{'err [deg]':>9} {'sigma':>6} {'false':>5}" +
              (f" {'stamp term':>10} {'err at true times':>17}" if clock else ""))
    for r in rows:
        u_from, u_to = int(r["from_utime_us"]), int(r["to_utime_us"])
        meas = (float(r["meas_x_m"]), float(r["meas_y_m"]), math.radians(float(r["meas_theta_deg"])))
        e = float(r["err_theta_deg"])  # true minus measured heading change
        w_from, w_to = truth.rate(u_from), truth.rate(u_to)
        dhdg = math.degrees(between(truth.at(u_from), truth.at(u_to))[2])
        err_before.append(e)
        if r["false"] == "1":
            flagged.append(e)
        line = (f"{r['from_id']:>5} {r['to_id']:>5} {1e-6 * (u_to - start):8.1f} {dhdg:10.1f} "
                f"{math.degrees(w_from):7.1f} {math.degrees(w_to):7.1f} {e:9.3f} "
                f"{float(r['sigma_theta_deg']):6.3f} {r['false']:>5}")
        if clock:
            t_from, t_to = true_time(u_from), true_time(u_to)
            # Heading error the evaluator sees from the stamps alone: truth at the stamp minus
            # truth at the true time, at either end.
            term = math.degrees(w_to * 1e-6 * (u_to - t_to) - w_from * 1e-6 * (u_from - t_from))
            t_true = between(truth.at(t_from), truth.at(t_to))
            e_after = math.degrees(wrap(t_true[2] - meas[2]))
            stamp_term.append(term)
            err_after.append(e_after)
            line += f" {term:10.3f} {e_after:17.3f}"
        if not args.json_only:
            print(line)
    out = {"closures": len(rows), "flagged_false": len(flagged),
           "heading_error_deg": spread(err_before),
           "flagged_heading_error_deg": spread(flagged),
           "flagged_same_sign": bool(flagged) and (all(v > 0 for v in flagged) or
                                                   all(v < 0 for v in flagged))}
    if clock:
        out["heading_error_at_true_times_deg"] = spread(err_after)
        out["stamp_term_deg"] = spread(stamp_term)
        out["correlation_error_stamp_term"] = correlation(err_before, stamp_term)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
