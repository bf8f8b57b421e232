#!/usr/bin/env python3
"""The backend's loop closures on a Kummerle log, checked against the benchmark's relations.

    scripts/closure_relations.py RUN_DIR_OR_LOG RELATIONS [--window-s S] [--sigmas K]
                                 [--build-dir DIR]

RUN_DIR_OR_LOG is an eval-kummerle.sh output folder of a run with the backend (its run.lcmlog)
or such a log; RELATIONS the benchmark's relations file (../shared/data/kummerle/NAME.relations:
t1 t2 x y z roll pitch yaw, the pose at t2 in the frame of the pose at t1, from hand-checked
scan alignment). The relations are ground truth between chosen pairs of scans; a closure
links two key poses at other times. A closure is checked where a relation has one end within
--window-s (default 2 s) of each of its key poses, either way round: the truth between the key
poses is then the frontend's own motion from the first key pose to the relation's scan, the
relation, and the frontend's motion from its other scan to the second key pose,

    T_true = F(from)^-1 F(t1) * R(t1, t2) * F(t2)^-1 F(to),

so the frontend's error over at most two windows enters the truth. That error is measured on the
same run, by the relations whose two scans lie within the window of each other (the mean of
e e^T of the frontend's relative pose against them, x and y made isotropic; none with fewer than
10 such relations), and added to the closure's covariance, carried through the composition, for
each bridge that is not empty (processes/evaluator/loop_closures.hpp does the same in C++). The
error is the one the pose graph minimises, e = t2v(Z^-1 T_true), and its Mahalanobis distance
uses the closure's published covariance plus the truth's. Beside it, the error of the frontend's own relative pose between the same two key
poses, F(from)^-1 F(to), against the same truth: a closure can only straighten the path where it
is nearer the truth than that. Prints the closures farthest from the truth in sigmas; the last
line is JSON: closures, checked, median and largest error [m, deg], the median and largest
Mahalanobis distance (median_sigmas, max_sigmas), how many lie over --sigmas (default 5), the frontend's median error over the same pairs [m, deg] and in
how many pairs the closure is nearer the truth than the frontend (closure_nearer).
"""
import argparse
import bisect
import json
import math
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lcmlog  # noqa: E402


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


def compose(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap(a[2] + b[2]))


def inverse(a):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2])


def det3(m):
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def adjoint(a):
    """Ad(T) of an SE(2) pose (x, y, theta): moves a twist (vx, vy, w) from T's frame out of it."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return [[c, -s, a[1]], [s, c, -a[0]], [0.0, 0.0, 1.0]]


def sandwich(a, m):
    """A M A^T for 3x3 matrices as lists of rows."""
    am = [[sum(a[i][k] * m[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    return [[sum(am[i][k] * a[j][k] for k in range(3)) for j in range(3)] for i in range(3)]


def bridge_covariance(pose_near, relations, window_us):
    """The frontend's error over spans up to window_us, measured by the relations that short."""
    sums, n = [0.0, 0.0, 0.0], 0
    for t1, t2, rel in relations:
        if abs(t2 - t1) > window_us:
            continue
        e = compose(inverse(rel), compose(inverse(pose_near(t1)), pose_near(t2)))
        sums = [sums[0] + e[0] ** 2, sums[1] + e[1] ** 2, sums[2] + e[2] ** 2]
        n += 1
    if n < 10:
        return [[0.0] * 3 for _ in range(3)]
    xy = 0.5 * (sums[0] + sums[1]) / n
    return [[xy, 0.0, 0.0], [0.0, xy, 0.0], [0.0, 0.0, sums[2] / n]]


def mahalanobis(e, c):
    """sqrt(e^T C^-1 e) for a 3x3 covariance C given row-major; nan when C is singular."""
    m = [c[0:3], c[3:6], c[6:9]]
    det = det3(m)
    if not det > 0.0:
        return float("nan")
    # C^-1 e by Cramer's rule: replace each column of C by e in turn.
    x = [det3([[e[i] if j == k else m[i][j] for j in range(3)] for i in range(3)]) / det
         for k in range(3)]
    return math.sqrt(max(0.0, sum(e[i] * x[i] for i in range(3))))


def read_run(path, build_dir=None):
    """Frontend poses {utime: (x, y, theta)} and the newest copy of each closure by key ids."""
    types = lcmlog.message_types(build_dir)
    frontend, closures = {}, {}
    for _, _, channel, data in lcmlog.events(path, channels={"POSE_FRONTEND", "KEY_POSES"}):
        if data is None:
            continue
        m = lcmlog.decode(types, data)
        if channel == "POSE_FRONTEND":
            frontend[m.utime] = (m.x, m.y, m.theta)
        else:
            for c in m.closures:
                closures[(c.from_id, c.to_id)] = c
    return frontend, closures


def read_relations(path):
    relations = []
    with open(path) as f:
        for line in f:
            p = line.split()
            if len(p) < 8 or line.startswith("#"):
                continue
            t1, t2 = round(float(p[0]) * 1e6), round(float(p[1]) * 1e6)
            relations.append((t1, t2, (float(p[2]), float(p[3]), float(p[7]))))
    return relations


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run")
    ap.add_argument("relations")
    ap.add_argument("--window-s", type=float, default=2.0)
    ap.add_argument("--sigmas", type=float, default=5.0)
    ap.add_argument("--build-dir", help="build folder with the generated types (default: build/)")
    a = ap.parse_args()
    log = os.path.join(a.run, "run.lcmlog") if os.path.isdir(a.run) else a.run
    frontend, closures = read_run(log, a.build_dir)
    if not frontend:
        sys.exit(f"{log}: no POSE_FRONTEND")
    times = sorted(frontend)

    def pose_near(utime):
        i = bisect.bisect_left(times, utime)
        j = min((k for k in (i - 1, i) if 0 <= k < len(times)), key=lambda k: abs(times[k] - utime))
        return frontend[times[j]]

    relations = read_relations(a.relations)
    window_us = a.window_s * 1e6
    bridge = bridge_covariance(pose_near, relations, window_us)
    checks = []
    for (from_id, to_id), c in sorted(closures.items()):
        best = None
        for t1, t2, r in relations:
            for ta, tb, rel in ((t1, t2, r), (t2, t1, inverse(r))):
                da, db = abs(ta - c.from_utime), abs(tb - c.utime)
                if da <= window_us and db <= window_us and (best is None or da + db < best[0]):
                    best = (da + db, ta, tb, rel)
        if best is None:
            continue
        _, ta, tb, rel = best
        to_a = compose(inverse(pose_near(c.from_utime)), pose_near(ta))
        from_b = compose(inverse(pose_near(tb)), pose_near(c.utime))
        truth = compose(compose(to_a, rel), from_b)
        e = compose(inverse((c.x, c.y, c.theta)), truth)
        # T_true = to_a * B, B = rel * from_b: an error d of to_a moves T_true by Ad(B^-1) d in its
        # own frame, an error of from_b by itself.
        cov = [[c.covariance[3 * i + j] for j in range(3)] for i in range(3)]
        for bridged, m in ((ta != c.from_utime, sandwich(adjoint(inverse(compose(rel, from_b))),
                                                          bridge)),
                           (tb != c.utime, bridge)):
            if bridged:
                cov = [[cov[i][j] + m[i][j] for j in range(3)] for i in range(3)]
        sigmas = mahalanobis(e, [v for row in cov for v in row])
        f = compose(inverse(compose(inverse(pose_near(c.from_utime)), pose_near(c.utime))), truth)
        checks.append((from_id, to_id, math.hypot(e[0], e[1]), math.degrees(e[2]), sigmas,
                       math.hypot(f[0], f[1]), math.degrees(f[2])))
    print(f"{len(closures)} closures, {len(checks)} with a relation within {a.window_s} s of both "
          f"key poses")
    for f, t, err_m, err_deg, s, fe_m, fe_deg in sorted(checks, key=lambda x: -x[4])[:8]:
        print(f"  {f} -> {t}: error {err_m:.3f} m, {err_deg:+.2f} deg, {s:.1f} sigmas "
              f"(frontend {fe_m:.3f} m, {fe_deg:+.2f} deg)")
    summary = {"closures": len(closures), "checked": len(checks), "window_s": a.window_s,
               "sigmas": a.sigmas, "bridge_sigma_m": round(math.sqrt(bridge[0][0]), 4),
               "bridge_sigma_deg": round(math.degrees(math.sqrt(bridge[2][2])), 3)}
    if checks:
        summary.update({
            "median_error_m": round(statistics.median(x[2] for x in checks), 4),
            "max_error_m": round(max(x[2] for x in checks), 4),
            "median_error_deg": round(statistics.median(abs(x[3]) for x in checks), 3),
            "max_error_deg": round(max(abs(x[3]) for x in checks), 3),
            "max_sigmas": round(max(x[4] for x in checks), 2),
            # 1.54 (sqrt of chi-square 3's median) when the covariances are right
            "median_sigmas": round(statistics.median(x[4] for x in checks), 2),
            "over_sigmas": sum(x[4] > a.sigmas for x in checks),
            "frontend_median_error_m": round(statistics.median(x[5] for x in checks), 4),
            "frontend_median_error_deg": round(statistics.median(abs(x[6]) for x in checks), 3),
            "closure_nearer": sum(x[2] + 1e-6 < x[5] for x in checks)})  # by over 1 um
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
