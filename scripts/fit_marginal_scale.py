#!/usr/bin/python3
"""The backend's marginal_scale fitted by NEES on recorded runs against the simulator's truth.

    scripts/fit_marginal_scale.py RUN.lcmlog [RUN.lcmlog ...] [--published-scale S]
                                  [--key-pose-sigma M] [--frame-heading-sigma RAD]

The backend publishes each key pose's covariance as marginal_scale times the graph's marginal,
plus the frame's heading term sigma^2 J J^T (J = (-(y - y0), x - x0): a turn about the first key
pose) and the key pose's own term (processes/backend/backend.cpp, published_covariance). sigma
is the boresight estimate's standard deviation while the estimate is applied, else
frame_heading_sigma_rad: it changes along a run, so it is read from the backend's status
(STATUS_BACKEND: boresight_yaw_rad, boresight_yaw_sigma_rad) in force when each key pose was last
published. Each run's log (a full run, or the compact log of scripts/eval-coverage.sh) gives, per
key pose, its position error against the truth (aligned at the first key pose, as
traverse-annotator-eval does) and its published covariance, split into the graph's part and the
two terms; the fit is the marginal_scale at which 95 % of the pooled key poses' NEES lie inside
the chi-square 95 % quantile of two degrees of freedom (5.991), with the two terms as they are.
Printed per run and pooled: the NEES q95 as published, the share inside the 95 % ellipse, the
scale that run alone would need (0: the two terms alone already hold 95 % of it), and the rms
turn about the first key pose its errors amount to beside the frame's sigma (median). The defaults of
the options are configs/backend.yaml's: the logs must have been made with it. JSON last.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import chain_errors  # noqa: E402
import lcmlog  # noqa: E402

CHI2_2_95 = 5.991464547107979
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_key_poses(path):
    """The truth and each key pose's newest (utime, pose, covariance, frame sigma or None), the
    frame sigma being the boresight's while the backend's status says it is applied."""
    types = lcmlog.message_types()
    ref, keys = [], {}
    boresight_sigma = None  # None: not applied, frame_heading_sigma_rad holds
    want = {"KEY_POSES", "POSE_GROUND_TRUTH", "STATUS_BACKEND"}
    for _o, _u, channel, data in lcmlog.events(path, channels=want):
        msg = lcmlog.decode(types, data) if data is not None else None
        if msg is None:
            continue
        if channel == "POSE_GROUND_TRUTH":
            ref.append((msg.utime, msg.x, msg.y, msg.theta))
        elif channel == "STATUS_BACKEND":
            c = dict(zip(msg.counter_names, msg.counter_values))
            applied = c.get("boresight_yaw_rad", 0.0) != 0.0
            boresight_sigma = c.get("boresight_yaw_sigma_rad") if applied else None
        else:
            for k in msg.poses:
                keys[k.id] = (k.utime, np.array([k.x, k.y, k.theta]),
                              np.array(k.covariance).reshape(3, 3), boresight_sigma)
    ref.sort(key=lambda p: p[0])
    return ref, keys


def decompose(ref, keys, published_scale, pose_sigma, frame_sigma):
    """Per key pose but the first: (error e, lever J, graph marginal M, frame sigma), 2D position
    parts, M being the published covariance less the two terms, over published_scale."""
    times = [r[0] for r in ref]
    rows = []
    for i, e, J in chain_errors.key_pose_errors(keys, ref, times):
        _, _, C, sigma = keys[i]
        s = frame_sigma if sigma is None else sigma
        M = (C[:2, :2] - s * s * np.outer(J, J) - pose_sigma ** 2 * np.eye(2)) / published_scale
        rows.append((e, J, M, s))
    return rows


def nees(rows, scale, pose_sigma):
    """e^T P^-1 e of every row with P = scale M + sigma^2 J J^T + pose_sigma^2 I (2 x 2, so the
    inverse in closed form, all rows at once)."""
    e = np.array([r[0] for r in rows])
    J = np.array([r[1] for r in rows])
    M = np.array([r[2] for r in rows])
    s2 = np.array([r[3] for r in rows]) ** 2
    P = scale * M + s2[:, None, None] * J[:, :, None] * J[:, None, :]
    P[:, 0, 0] += pose_sigma ** 2
    P[:, 1, 1] += pose_sigma ** 2
    det = P[:, 0, 0] * P[:, 1, 1] - P[:, 0, 1] * P[:, 1, 0]
    quad = (P[:, 1, 1] * e[:, 0] ** 2 - (P[:, 0, 1] + P[:, 1, 0]) * e[:, 0] * e[:, 1] +
            P[:, 0, 0] * e[:, 1] ** 2)
    return quad / det


def turn_rms(rows, min_distance_m=5.0):
    """[rad] The part of each error across the line from the first key pose over its distance, rms
    over the key poses beyond min_distance_m: what a turn of the frame about the first key pose
    would explain (to hold against the frame's sigma), slips along the path adding to it too."""
    turns = [float(e @ J) / float(J @ J) for e, J, _, _ in rows if J @ J > min_distance_m ** 2]
    return float(np.sqrt(np.mean(np.square(turns)))) if turns else 0.0


def fit_scale(rows, pose_sigma, lo=1e-3, hi=1e6):
    """The scale at which the NEES q95 is 5.991 (it falls as the scale grows): 0 when the two
    terms alone bring it under, hi when no scale up to hi does."""
    def q95(scale):
        return np.quantile(nees(rows, scale, pose_sigma), 0.95)
    if q95(lo) <= CHI2_2_95:
        return 0.0
    if q95(hi) > CHI2_2_95:
        return hi
    for _ in range(60):  # bisection in log scale: to 1e-7 relative
        mid = (lo * hi) ** 0.5
        lo, hi = (mid, hi) if q95(mid) > CHI2_2_95 else (lo, mid)
    return hi


def backend_config():
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    import conf  # noqa: E402
    return conf.load(os.path.join(ROOT, "configs", "backend.yaml"))["backend"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("logs", nargs="+")
    config = backend_config()
    ap.add_argument("--published-scale", type=float, default=config["marginal_scale"],
                    help="the marginal_scale the logs were published with")
    ap.add_argument("--key-pose-sigma", type=float, default=config["key_pose_sigma_xy_m"],
                    help="[m] key_pose_sigma_xy_m the logs were published with")
    ap.add_argument("--frame-heading-sigma", type=float,
                    default=config["frame_heading_sigma_rad"],
                    help="[rad] frame_heading_sigma_rad (before the boresight estimate holds)")
    args = ap.parse_args()
    runs, rows_of, pooled = {}, {}, []
    for path in args.logs:
        rows = decompose(*read_key_poses(path), args.published_scale, args.key_pose_sigma,
                         args.frame_heading_sigma)
        if not rows:
            sys.exit(f"fit_marginal_scale: no key poses with truth in {path}")
        n = nees(rows, args.published_scale, args.key_pose_sigma)
        name = os.path.basename(os.path.dirname(os.path.abspath(path))) or path
        runs[name] = {"key_poses": len(rows), "nees_q95": float(np.quantile(n, 0.95)),
                      "inside_95": float(np.mean(n <= CHI2_2_95)),
                      "own_marginal_scale": fit_scale(rows, args.key_pose_sigma),
                      "turn_rms_rad": turn_rms(rows),
                      "frame_sigma_median_rad": float(np.median([r[3] for r in rows]))}
        rows_of[name] = rows
        pooled += rows
    scale = fit_scale(pooled, args.key_pose_sigma)
    print(f"published with marginal_scale {args.published_scale:g}, key pose sigma "
          f"{args.key_pose_sigma:g} m, frame heading sigma {args.frame_heading_sigma:g} rad "
          "before the boresight holds")
    print(f"{'run':64} {'key poses':>9} {'NEES q95':>8} {'inside':>6} {'own scale':>9} "
          f"{'turn rms [mrad]':>15} {'frame sigma [mrad]':>18}  at the fitted scale: NEES q95, inside")
    for name, r in runs.items():
        rows_n = nees(rows_of[name], scale, args.key_pose_sigma)
        r["fitted_nees_q95"] = float(np.quantile(rows_n, 0.95))
        r["fitted_inside_95"] = float(np.mean(rows_n <= CHI2_2_95))
        print(f"{name:64} {r['key_poses']:9d} {r['nees_q95']:8.2f} {r['inside_95']:6.3f} "
              f"{r['own_marginal_scale']:9.1f} {1e3 * r['turn_rms_rad']:15.2f} "
              f"{1e3 * r['frame_sigma_median_rad']:18.2f}  {r['fitted_nees_q95']:.2f}, "
              f"{r['fitted_inside_95']:.3f}")
    print(f"marginal_scale fitted on {len(runs)} runs ({len(pooled)} key poses): {scale:.4g}")
    print(json.dumps({"marginal_scale": scale, "published_scale": args.published_scale,
                      "key_poses": len(pooled), "runs": runs}))


if __name__ == "__main__":
    main()
