#!/usr/bin/python3
"""scripts/fit_marginal_scale.py on synthetic key poses whose errors are drawn from a known
covariance: the published covariance splits back into the graph's marginal and the two terms,
and the fit finds the scale the errors were drawn with."""
import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "scripts"))
import fit_marginal_scale as fit  # noqa: E402

POSE_SIGMA = 0.01  # [m]


def synthetic_run(true_scale, frame_sigma, n=3000, seed=7, terms_factor=1.0):
    """Key poses along a 60 m loop; the graph's marginals grow with the distance; the errors
    drawn from true_scale * M + terms_factor * (the two terms)."""
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(n):
        a = 2.0 * math.pi * i / n
        J = np.array([-10.0 * math.sin(a), 10.0 * (1.0 - math.cos(a))])
        d = 1e-6 * (1.0 + i / n)  # [m^2] before the scale
        c = 0.3 * d * math.sin(3.0 * a)
        M = np.array([[d, c], [c, 2.0 * d]])
        terms = frame_sigma ** 2 * np.outer(J, J) + POSE_SIGMA ** 2 * np.eye(2)
        e = rng.multivariate_normal(np.zeros(2), true_scale * M + terms_factor * terms)
        rows.append((e, J, M, frame_sigma))
    return rows


class FitMarginalScaleTest(unittest.TestCase):
    def test_finds_the_scale_the_errors_were_drawn_with(self):
        for true_scale in (50.0, 400.0):
            got = fit.fit_scale(synthetic_run(true_scale, 0.0005), POSE_SIGMA)
            self.assertLess(abs(got / true_scale - 1.0), 0.15, (true_scale, got))

    def test_pooled_fit_lies_between_the_runs(self):
        small, large = synthetic_run(20.0, 0.0005, seed=1), synthetic_run(500.0, 0.0005, seed=2)
        pooled = fit.fit_scale(small + large, POSE_SIGMA)
        self.assertGreater(pooled, fit.fit_scale(small, POSE_SIGMA))
        self.assertLess(pooled, fit.fit_scale(large, POSE_SIGMA))

    def test_zero_when_the_two_terms_alone_cover(self):
        rows = synthetic_run(0.0, 0.0005, terms_factor=0.25)
        self.assertEqual(fit.fit_scale(rows, POSE_SIGMA), 0.0)

    def test_published_covariance_splits_back(self):
        # Truth along x, the estimate off by (0.03, -0.02) m at key pose 1; published with
        # scale 167, a boresight sigma of 0.5 mrad (from the status) and 1 cm per key pose.
        ref = [(0, 0.0, 0.0, 0.0), (100, 10.0, 0.0, 0.0), (200, 20.0, 0.0, 0.0)]
        M = np.array([[4e-6, 1e-6, 0.0], [1e-6, 9e-6, 0.0], [0.0, 0.0, 1e-8]])
        J = np.array([0.02, 10.03])  # from the published positions, as the backend forms it
        C = 167.0 * M
        C[:2, :2] += 0.0005 ** 2 * np.outer(J, J) + POSE_SIGMA ** 2 * np.eye(2)
        keys = {0: (0, np.zeros(3), np.zeros((3, 3)), None),
                1: (100, np.array([10.03, -0.02, 0.0]), C, 0.0005)}
        rows = fit.decompose(ref, keys, 167.0, POSE_SIGMA, 0.0036)
        self.assertEqual(len(rows), 1)
        e, J_got, M_got, s = rows[0]
        np.testing.assert_allclose(e, [0.03, -0.02], atol=1e-12)
        np.testing.assert_allclose(J_got, J, atol=1e-12)
        np.testing.assert_allclose(M_got, M[:2, :2], rtol=1e-9, atol=1e-15)
        self.assertEqual(s, 0.0005)
        # Before the boresight holds (no sigma from the status), frame_heading_sigma_rad.
        keys[1] = (100, keys[1][1], keys[1][2], None)
        self.assertEqual(fit.decompose(ref, keys, 167.0, POSE_SIGMA, 0.0036)[0][3], 0.0036)


if __name__ == "__main__":
    unittest.main()
