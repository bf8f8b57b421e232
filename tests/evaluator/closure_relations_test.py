#!/usr/bin/python3
"""traverse-evaluator --relations checking loop closures on a crafted run: a cart on a 10 m circle
(so headings matter and a relation's yaw, its 8th field, must be read), the frontend exactly on
it, and three closures: one exact, one 0.3 m off, one with no relation near its key poses. The
check must find the first within a sigma, the second far over 5 sigmas, and leave the third
unchecked.

    closure_relations_test.py BUILD_DIR
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPTS = os.path.join(HERE, "..", "..", "scripts")
sys.path.insert(0, SCRIPTS)
import lcmlog  # noqa: E402

BUILD = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "..", "..", "build")
sys.path.insert(0, os.path.join(BUILD, "python"))
from traverse import key_poses_t, loop_closure_t, pose2d_t  # noqa: E402


def pose(t):
    """The cart at t [s]: 1 m/s on a circle of 10 m radius."""
    a = t / 10.0
    return (10.0 * math.sin(a), 10.0 * (1.0 - math.cos(a)), math.atan2(math.sin(a), math.cos(a)))


def between(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return (c * dx + s * dy, -s * dx + c * dy, math.atan2(math.sin(b[2] - a[2]), math.cos(b[2] - a[2])))


def utime(t):
    return round(t * 1e6)


def closure(from_id, t_from, to_id, t_to, offset_m):
    z = between(pose(t_from), pose(t_to))
    c = loop_closure_t()
    c.utime, c.from_utime, c.from_id, c.to_id = utime(t_to), utime(t_from), from_id, to_id
    c.x, c.y, c.theta = z[0] + offset_m, z[1], z[2]
    c.covariance = [0.02 ** 2, 0, 0, 0, 0.02 ** 2, 0, 0, 0, 0.005 ** 2]
    c.response, c.candidates = 0.9, 1
    return c


class ClosureRelationsTest(unittest.TestCase):
    def test_exact_and_wrong_closures(self):
        with tempfile.TemporaryDirectory() as d:
            events = []
            for k in range(0, 1001):  # 0 .. 100 s every 0.1 s
                t = k / 10.0
                p = pose(t)
                m = pose2d_t()
                m.utime, m.seq, m.parent_frame, m.child_frame = utime(t), k, "map", "base"
                m.x, m.y, m.theta = p
                m.covariance = [0.0] * 9
                m.flags = 0
                events.append((utime(t), "POSE_FRONTEND", m.encode()))
            keys = key_poses_t()
            keys.utime, keys.seq, keys.optimisation, keys.part, keys.parts = utime(100), 0, 1, 0, 1
            keys.total_key_poses, keys.total_loop_closures = 0, 3
            keys.optimisation_s, keys.chi2 = 0.0, 0.0
            keys.n_poses, keys.poses = 0, []
            keys.closures = [closure(100, 10.0, 500, 50.0, 0.0), closure(200, 20.0, 700, 70.0, 0.3),
                             closure(300, 30.0, 350, 35.0, 0.0)]
            keys.n_closures = len(keys.closures)
            events.append((utime(100) + 1, "KEY_POSES", keys.encode()))
            log = os.path.join(d, "run.lcmlog")
            lcmlog.write_events(log, events)
            # Relations between scans near (not at) the closures' key poses, in the benchmark's
            # format: t1 t2 x y z roll pitch yaw.
            relations = os.path.join(d, "test.relations")
            with open(relations, "w") as f:
                for t1, t2 in ((10.5, 49.2), (71.0, 19.4)):
                    r = between(pose(t1), pose(t2))
                    f.write(f"{t1:.6f} {t2:.6f} {r[0]:.6f} {r[1]:.6f} 0 0 0 {r[2]:.6f}\n")
            out_dir = os.path.join(d, "out")
            out = subprocess.run(
                [os.path.join(BUILD, "bin", "traverse-evaluator"), "--log", log, "--relations",
                 relations, "--out", out_dir], capture_output=True, text=True, check=True).stdout
            summary = json.loads(out.strip().splitlines()[-1])
            self.assertEqual(summary["frontend_poses"], 1001)
            self.assertEqual(summary["window_s"], 2.0)
            self.assertEqual(summary["sigmas"], 5.0)
            self.assertEqual(summary["closures"], 3)
            self.assertEqual(summary["checked"], 2)  # 30 -> 35 s has no relation near it
            self.assertEqual(summary["over_sigmas"], 1)
            self.assertAlmostEqual(summary["max_error_m"], 0.3, delta=0.005)
            self.assertGreater(summary["max_sigmas"], 10.0)
            # Two checked: the median is the mean of the two, as statistics.median's.
            self.assertAlmostEqual(summary["median_error_m"], 0.15, delta=0.003)
            with open(os.path.join(out_dir, "closures.csv")) as f:
                rows = {(r["from_id"], r["to_id"]): r for r in csv.DictReader(f)}
            self.assertAlmostEqual(float(rows[("100", "500")]["err_xy_m"]), 0.0, delta=1e-4)
            self.assertAlmostEqual(float(rows[("200", "700")]["err_xy_m"]), 0.3, delta=0.005)
            self.assertEqual(rows[("200", "700")]["false"], "1")
            self.assertEqual(rows[("300", "350")]["matched"], "0")
            self.assertEqual(rows[("300", "350")]["frontend_err_xy_m"], "")
            # The frontend lies on the truth: no closure is nearer to it.
            self.assertLess(summary["frontend_median_error_m"], 1e-4)
            self.assertEqual(summary["closure_nearer"], 0)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
