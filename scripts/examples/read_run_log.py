#!/usr/bin/env python3
"""Example: reads a recorded run (e.g. out/demo/run.lcmlog) with the generated Python types and
prints, per channel, the message count, type and time span, then the frontend's last pose and
the backend's loop closures.

    python3 scripts/examples/read_run_log.py out/demo/run.lcmlog
"""
import os
import sys
from collections import defaultdict

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import lcmlog  # noqa: E402  (scripts/lcmlog.py)


def main(path):
    types = lcmlog.message_types()
    count = defaultdict(int)
    type_of, first, last = {}, {}, {}
    last_pose, closures = None, 0
    for _offset, utime, channel, data in lcmlog.events(path):
        msg = lcmlog.decode(types, data)
        count[channel] += 1
        type_of[channel] = type(msg).__name__ if msg is not None else "(unknown)"
        first.setdefault(channel, utime)
        last[channel] = utime
        if channel == "POSE_FRONTEND" and msg is not None:
            last_pose = msg
        if channel == "KEY_POSES" and msg is not None:
            closures += msg.n_closures
    print(f"{'channel':28} {'type':20} {'messages':>9} {'span [s]':>9}")
    for channel in sorted(count):
        span = (last[channel] - first[channel]) * 1e-6
        print(f"{channel:28} {type_of[channel]:20} {count[channel]:9d} {span:9.1f}")
    if last_pose is not None:
        print(f"last frontend pose: x {last_pose.x:.3f} m, y {last_pose.y:.3f} m, "
              f"theta {last_pose.theta:.4f} rad in frame {last_pose.parent_frame}")
    print(f"loop closures added by the backend: {closures}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
