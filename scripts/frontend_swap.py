#!/usr/bin/env python3
"""Helpers of scripts/frontend-swap.sh.

  frontend_swap.py insert IN OUT FRACTION KIND   OUT = IN with one frontend_control_t request
                                                 (FRONTEND_CONTROL, request_id 1) inserted after
                                                 FRACTION of IN's horizontal scans; prints its
                                                 time [us]
  frontend_swap.py jump LOG SWAP_UTIME [N]       the largest step error [m] of the N (10) frontend
                                                 poses either side of SWAP_UTIME: the frontend's
                                                 step between consecutive poses against the
                                                 ground truth's over the same interval (JSON)
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lcmlog  # noqa: E402


def insert(src, dst, fraction, kind):
    types = lcmlog.message_types()
    control = next(c for c in types.values() if c.__name__ == "frontend_control_t")
    scans = [t for _, t, ch, _ in lcmlog.events(src, channels={"SCAN_HORIZONTAL"})
             if ch == "SCAN_HORIZONTAL"]
    if not scans:
        sys.exit(f"{src}: no SCAN_HORIZONTAL")
    at = scans[min(len(scans) - 1, int(fraction * len(scans)))]
    msg = control()
    msg.utime = at
    msg.seq = 0
    msg.request_id = 1
    msg.kind = kind
    items, placed = [], False
    for _, utime, channel, data in lcmlog.events(src):
        if not placed and utime > at:
            items.append((at, "FRONTEND_CONTROL", msg.encode()))
            placed = True
        items.append((utime, channel, data))
    lcmlog.write_events(dst, items)
    print(at)


def poses(path, channel, types):
    out = []
    for _, _, ch, data in lcmlog.events(path, channels={channel}):
        if ch == channel:
            m = lcmlog.decode(types, data)
            if m is not None:
                out.append((m.utime, m.x, m.y, m.theta))
    return sorted(out)


def truth_at(truth, utime):
    # Linear between the two ground-truth poses around utime (they come at hundreds of Hz).
    lo, hi = 0, len(truth) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if truth[mid][0] <= utime:
            lo = mid
        else:
            hi = mid
    a, b = truth[lo], truth[hi]
    f = 0.0 if b[0] == a[0] else min(1.0, max(0.0, (utime - a[0]) / (b[0] - a[0])))
    return a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])


def jump(path, swap_utime, n):
    types = lcmlog.message_types()
    est = poses(path, "POSE_FRONTEND", types)
    truth = poses(path, "POSE_GROUND_TRUTH", types)
    # The frontend's map frame is the base at its first pose: truth is turned into it.
    h0 = est[0][3] - next(p[3] for p in truth if p[0] >= est[0][0])
    c, s = math.cos(h0), math.sin(h0)
    k = next(i for i, p in enumerate(est) if p[0] > swap_utime)
    worst, at = 0.0, None
    for i in range(max(1, k - n), min(len(est), k + n)):
        (ua, xa, ya, _), (ub, xb, yb, _) = est[i - 1], est[i]
        ta, tb = truth_at(truth, ua), truth_at(truth, ub)
        dx, dy = tb[0] - ta[0], tb[1] - ta[1]
        err = math.hypot((xb - xa) - (c * dx - s * dy), (yb - ya) - (s * dx + c * dy))
        if err > worst:
            worst, at = err, ub
    print(json.dumps({"swap_step_error_max_m": worst, "at_utime": at,
                      "first_pose_after_swap_utime": est[k][0]}))


if __name__ == "__main__":
    if len(sys.argv) == 6 and sys.argv[1] == "insert":
        insert(sys.argv[2], sys.argv[3], float(sys.argv[4]), sys.argv[5])
    elif len(sys.argv) in (4, 5) and sys.argv[1] == "jump":
        jump(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]) if len(sys.argv) == 5 else 10)
    else:
        sys.exit(__doc__)
