#!/usr/bin/python3
"""How a trajectory's errors grow against the truth (or a reference), and whether the
covariances published with it match them: the figures the backend's chain model
(configs/backend.yaml, processes/backend/frontend_chain.hpp) and the closures' covariances are
fitted to.

    scripts/chain_errors.py RUN.lcmlog [--estimate POSE_FRONTEND] [--reference POSE_GROUND_TRUTH]

Reads the estimate's poses (pose2d_t, the map frame) and the reference's (interpolated to the
estimate's times; the simulator's truth in its world frame, or a CARMEN log's reference, which is
another estimate and not the truth), and prints:
  - per separation d along the path (0.5 to 50 m of travel): the RMS heading error [rad] and
    position error [m] of the relative pose of two poses d apart, in the first one's frame;
  - a random walk fitted to them: heading variance = 2 s0^2 + q_theta d, position variance of
    what the heading does not explain = 2 p0^2 + q_xy d (rad^2/m and m^2/m: the sigma a random
    walk reaches after one metre is sqrt(q));
  - the NEES of the published covariances on steps of 0.5 m (both poses' covariances carried
    into the relative pose; chi-square with 3 degrees of freedom, mean 3, if they are right);
  - with the backend's KEY_POSES in the log: every loop closure's error against the reference
    and its NEES with the published covariance (mean 3 if right), and each closure's sigmas;
    and the key poses' own position errors (the reference aligned at the first key pose, as
    traverse-annotator-eval does) against their published marginals: NEES (chi-square with 2
    degrees of freedom if right: mean 2, 95 % under 5.991), with --frame-heading-sigma and
    --key-pose-sigma added to the marginals as the backend's config keys of those names would
    (to try them without running the backend again).
The last line is JSON with the same figures.
"""
import argparse
import bisect
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lcmlog  # noqa: E402

SEPARATIONS_M = [0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0]
S = np.array([[0.0, -1.0], [1.0, 0.0]])


def wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def rot(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s], [s, c]])


def read(path, estimate, reference):
    types = lcmlog.message_types()
    est, ref, closures, keys = [], [], [], {}
    want = {estimate, reference, "KEY_POSES"}
    for _o, _u, channel, data in lcmlog.events(path, channels=want):
        if data is None:
            continue
        msg = lcmlog.decode(types, data)
        if msg is None:
            continue
        if channel == estimate:
            est.append((msg.utime, msg.x, msg.y, msg.theta, np.array(msg.covariance).reshape(3, 3)))
        elif channel == reference:
            ref.append((msg.utime, msg.x, msg.y, msg.theta))
        elif channel == "KEY_POSES":
            closures += list(msg.closures)
            for k in msg.poses:  # the newest of each key pose
                keys[k.id] = (k.utime, np.array([k.x, k.y, k.theta]),
                              np.array(k.covariance).reshape(3, 3))
    est.sort(key=lambda p: p[0])
    ref.sort(key=lambda p: p[0])
    return est, ref, closures, keys


def key_pose_errors(keys, ref, times):
    """Per key pose but the first, (id, e, J): its position error e against the reference aligned
    so that the first key pose is exact, and J, the lever of a turn of the frame about the first
    key pose (d position / d heading). `keys`: id -> (utime, pose, ...)."""
    ids = sorted(keys)
    if len(ids) < 2:
        return []
    u0, p0 = keys[ids[0]][:2]
    g0 = interpolate(ref, times, u0)
    if g0 is None:
        return []
    out = []
    for i in ids[1:]:
        u, p = keys[i][:2]
        g = interpolate(ref, times, u)
        if g is None:
            continue
        rel = relative(g0, g)
        e = p[:2] - (p0[:2] + rot(p0[2]) @ rel[:2])
        r = p[:2] - p0[:2]
        out.append((i, e, np.array([-r[1], r[0]])))
    return out


def key_pose_nees(keys, ref, times, frame_sigma, pose_sigma, scale=1.0, held=(0.0, 0.0)):
    """NEES of each key pose's position error against its marginal (the reference aligned at the
    first key pose): the graph's part (the published marginal less the terms `held` it was
    published with) times `scale`, plus the two reporting terms."""
    out = []
    for i, e, J in key_pose_errors(keys, ref, times):
        C = keys[i][2]
        G = C[:2, :2] - held[0] ** 2 * np.outer(J, J) - held[1] ** 2 * np.eye(2)
        P = scale * G + frame_sigma ** 2 * np.outer(J, J) + pose_sigma ** 2 * np.eye(2)
        try:
            out.append(float(e @ np.linalg.solve(P, e)))
        except np.linalg.LinAlgError:
            pass
    return out


def interpolate(ref, times, utime):
    i = bisect.bisect_left(times, utime)
    if i == 0 or i >= len(ref):
        if 0 <= i < len(ref) and ref[i][0] == utime:
            return np.array(ref[i][1:4])
        return None
    a, b = ref[i - 1], ref[i]
    if b[0] - a[0] > 500000:  # a gap in the reference: no truth here
        return None
    f = (utime - a[0]) / max(1, b[0] - a[0])
    return np.array([a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]),
                     a[3] + f * wrap(b[3] - a[3])])


def relative(a, b):
    """b in a's frame: (x, y, theta)."""
    d = rot(a[2]).T @ (b[:2] - a[:2])
    return np.array([d[0], d[1], wrap(b[2] - a[2])])


def relative_error(ea, eb, ta, tb):
    """The estimate's relative pose against the reference's, in a's frame."""
    re, rt = relative(ea, eb), relative(ta, tb)
    dt = rot(rt[2]).T @ (re[:2] - rt[:2])
    return np.array([re[0] - rt[0], re[1] - rt[1], wrap(re[2] - rt[2])]), dt


def relative_covariance(a, b, ca, cb):
    """Both poses' map-frame covariances carried into the relative pose (in a's frame)."""
    R = rot(a[2])
    d = b[:2] - a[:2]
    Ja = np.zeros((3, 3))
    Ja[:2, :2] = -R.T
    Ja[:2, 2] = -R.T @ S @ d
    Ja[2, 2] = -1.0
    Jb = np.zeros((3, 3))
    Jb[:2, :2] = R.T
    Jb[2, 2] = 1.0
    return Ja @ ca @ Ja.T + Jb @ cb @ Jb.T


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("log")
    ap.add_argument("--estimate", default="POSE_FRONTEND")
    ap.add_argument("--reference", default="POSE_GROUND_TRUTH")
    ap.add_argument("--frame-heading-sigma", type=float, default=0.0, help="[rad]")
    ap.add_argument("--key-pose-sigma", type=float, default=0.0, help="[m]")
    ap.add_argument("--marginal-scale", type=float, default=1.0,
                    help="the graph's marginals times this (the backend's marginal_scale)")
    ap.add_argument("--published-with", type=float, nargs=2, default=[0.0, 0.0],
                    metavar=("FRAME_RAD", "POSE_M"),
                    help="the frame and key pose terms the log's marginals were published with")
    args = ap.parse_args()
    est, ref, closures, keys = read(args.log, args.estimate, args.reference)
    if (len(est) < 2 and not keys) or len(ref) < 2:
        sys.exit(f"chain_errors: too few poses on {args.estimate} ({len(est)}) or "
                 f"{args.reference} ({len(ref)}) in {args.log}")
    times = [r[0] for r in ref]
    poses, truth, covs, travel = [], [], [], []
    for u, x, y, t, c in est:
        g = interpolate(ref, times, u)
        if g is None:
            continue
        e = np.array([x, y, t])
        travel.append(travel[-1] + float(np.linalg.norm(g[:2] - truth[-1][:2])) if truth else 0.0)
        poses.append(e)
        truth.append(g)
        covs.append(c)
    n = len(poses)
    if n < 2:  # key poses only (a compact log): their NEES below
        poses, truth, covs, travel = [], [], [], [0.0]
    result = {"log": args.log, "estimate": args.estimate, "reference": args.reference,
              "poses": n, "travel_m": travel[-1] if travel else 0.0, "separations": []}
    # Pairs start every 0.25 m of travel.
    starts, next_start = [], 0.0
    for i in range(n):
        if travel[i] >= next_start:
            starts.append(i)
            next_start = travel[i] + 0.25
    print(f"{args.log}: {n} poses on {args.estimate} against {args.reference}, "
          f"{result['travel_m']:.1f} m of travel")
    print(f"{'d [m]':>6} {'pairs':>6} {'heading rms [rad]':>17} {'position rms [m]':>16} "
          f"{'lateral rms [m]':>15} {'NEES mean':>9}")
    fit_rows = []
    for d in SEPARATIONS_M:
        eth, epos, elat, nees = [], [], [], []
        for i in starts:
            j = bisect.bisect_left(travel, travel[i] + d)
            if j >= n:
                break
            err, _ = relative_error(poses[i], poses[j], truth[i], truth[j])
            eth.append(err[2])
            epos.append(float(np.hypot(err[0], err[1])))
            # What the heading error at the start does not explain: the error of j's position
            # in i's frame, less the lever of i's heading error (unknown: taken as the part
            # of the error across the direction of travel).
            rt = relative(truth[i], truth[j])
            along = rt[:2] / max(1e-9, float(np.linalg.norm(rt[:2])))
            elat.append(float(abs(along[0] * err[1] - along[1] * err[0])))
            if d == SEPARATIONS_M[0] and not (covs[i] == 0).all() and not (covs[j] == 0).all():
                C = relative_covariance(poses[i], poses[j], covs[i], covs[j])
                try:
                    nees.append(float(err @ np.linalg.solve(C, err)))
                except np.linalg.LinAlgError:
                    pass
        if not eth:
            continue
        row = {"d_m": d, "pairs": len(eth),
               "heading_rms_rad": float(np.sqrt(np.mean(np.square(eth)))),
               "position_rms_m": float(np.sqrt(np.mean(np.square(epos)))),
               "lateral_rms_m": float(np.sqrt(np.mean(np.square(elat))))}
        if nees:
            row.update({"nees_mean": float(np.mean(nees)), "nees_median": float(np.median(nees)),
                        "nees_q95": float(np.quantile(nees, 0.95))})
        result["separations"].append(row)
        fit_rows.append(row)
        print(f"{d:6.1f} {len(eth):6d} {row['heading_rms_rad']:17.5f} "
              f"{row['position_rms_m']:16.4f} {row['lateral_rms_m']:15.4f} "
              f"{row.get('nees_mean', float('nan')):9.1f}")
    if len(fit_rows) >= 2:
        # Least squares of variance = a + q d on the separations (weighting each equally).
        dd = np.array([r["d_m"] for r in fit_rows])
        A = np.vstack([np.ones_like(dd), dd]).T
        vt = np.array([r["heading_rms_rad"] ** 2 for r in fit_rows])
        vp = np.array([r["position_rms_m"] ** 2 for r in fit_rows])
        (at, qt), (ap_, qp) = np.linalg.lstsq(A, vt, rcond=None)[0], np.linalg.lstsq(A, vp, rcond=None)[0]
        result["fit"] = {"heading_q_rad2_per_m": float(qt), "heading_s0_rad": math.sqrt(max(0.0, at / 2)),
                         "position_q_m2_per_m": float(qp), "position_p0_m": math.sqrt(max(0.0, ap_ / 2))}
        print(f"random walk: heading sigma after 1 m {math.sqrt(max(qt, 0)):.5f} rad "
              f"(s0 {result['fit']['heading_s0_rad']:.5f} rad), position sigma after 1 m "
              f"{math.sqrt(max(qp, 0)):.4f} m (p0 {result['fit']['position_p0_m']:.4f} m)")
    if closures:
        rows = []
        for c in closures:
            ga = interpolate(ref, times, c.from_utime)
            gb = interpolate(ref, times, c.utime)
            if ga is None or gb is None:
                continue
            rt = relative(ga, gb)
            meas = np.array([c.x, c.y, c.theta])
            # Error in to's base frame (the frame of the published covariance).
            dt = rot(rt[2]).T @ (meas[:2] - rt[:2])
            err = np.array([dt[0], dt[1], wrap(meas[2] - rt[2])])
            C = np.array(c.covariance).reshape(3, 3)
            nees = float(err @ np.linalg.solve(C, err))
            rows.append({"from_id": c.from_id, "to_id": c.to_id, "error_xy_m": float(np.hypot(*err[:2])),
                         "error_theta_rad": float(err[2]), "sigma_x_m": math.sqrt(C[0, 0]),
                         "sigma_y_m": math.sqrt(C[1, 1]), "sigma_theta_rad": math.sqrt(C[2, 2]),
                         "nees": nees})
        if rows:
            nees = [r["nees"] for r in rows]
            result["closures"] = {"count": len(rows), "nees_mean": float(np.mean(nees)),
                                  "nees_median": float(np.median(nees)),
                                  "outside_99": float(np.mean(np.array(nees) > 11.34)),
                                  "error_xy_rms_m": float(np.sqrt(np.mean([r["error_xy_m"] ** 2 for r in rows]))),
                                  "error_theta_rms_rad": float(np.sqrt(np.mean([r["error_theta_rad"] ** 2 for r in rows]))),
                                  "sigma_xy_median_m": float(np.median([max(r["sigma_x_m"], r["sigma_y_m"]) for r in rows])),
                                  "sigma_theta_median_rad": float(np.median([r["sigma_theta_rad"] for r in rows])),
                                  "items": rows}
            c = result["closures"]
            print(f"closures: {c['count']}, NEES mean {c['nees_mean']:.1f} median {c['nees_median']:.1f} "
                  f"(3 if right), {100 * c['outside_99']:.0f} % outside the 99 % ellipsoid; error rms "
                  f"{c['error_xy_rms_m']:.4f} m / {c['error_theta_rms_rad']:.5f} rad against median sigmas "
                  f"{c['sigma_xy_median_m']:.4f} m / {c['sigma_theta_median_rad']:.5f} rad")
    if keys:
        nees = key_pose_nees(keys, ref, times, args.frame_heading_sigma, args.key_pose_sigma,
                             args.marginal_scale, tuple(args.published_with))
        if nees:
            a = np.array(nees)
            result["key_poses"] = {"count": len(nees), "marginal_scale": args.marginal_scale,
                                   "frame_heading_sigma_rad": args.frame_heading_sigma,
                                   "key_pose_sigma_m": args.key_pose_sigma,
                                   "nees_mean": float(a.mean()), "nees_median": float(np.median(a)),
                                   "nees_q95": float(np.quantile(a, 0.95)),
                                   "inside_95": float(np.mean(a <= 5.991)),
                                   "scale_for_95": float(np.quantile(a, 0.95) / 5.991)}
            k = result["key_poses"]
            print(f"key poses: {k['count']}, NEES mean {k['nees_mean']:.2f} median {k['nees_median']:.2f} "
                  f"q95 {k['nees_q95']:.2f} (2, 1.39, 5.99 if right), inside the 95 % ellipse "
                  f"{k['inside_95']:.3f}, scale for 95 % {k['scale_for_95']:.3g}")
    print(json.dumps(result))


if __name__ == "__main__":
    main()
