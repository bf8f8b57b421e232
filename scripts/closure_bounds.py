#!/usr/bin/python3
"""What each loop closure did to the annotator's bounds near it, in a recorded run.

    scripts/closure_bounds.py RUN.lcmlog [--near-m 10]

Follows the backend's KEY_POSES (positions, closures) and the annotator's ANNOTATIONS in log
order. At each annotation update published for a loop closure (REASON_LOOP_CLOSURE), the key
poses republished there that lie within --near-m of one of the closure's key poses are compared
with their previous annotation: how many, their median bound before and after [mm], the median
and smallest ratio after / before, and how many changed level. The last line is JSON, one object
per closure update. The same selection as tests/annotator/court_closure_test.cpp.
"""
import argparse
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lcmlog  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log")
    ap.add_argument("--near-m", type=float, default=10.0, help="[m] radius around a closure's key poses")
    args = ap.parse_args()
    types = lcmlog.message_types()
    position, annotation, closure_ids, rows, current = {}, {}, [], [], None

    def near(i):
        p = position.get(i)
        return p is not None and any(
            c in position and (p[0] - position[c][0]) ** 2 + (p[1] - position[c][1]) ** 2 < args.near_m**2
            for c in closure_ids)

    for _, _, channel, data in lcmlog.events(args.log, channels={"KEY_POSES", "ANNOTATIONS"}):
        if data is None:
            continue
        msg = lcmlog.decode(types, data)
        if msg is None:
            continue
        if channel == "KEY_POSES":
            for k in msg.poses:
                position[k.id] = (k.x, k.y)
            for c in msg.closures:
                closure_ids += [c.from_id, c.to_id]
            continue
        closure = msg.reason == msg.REASON_LOOP_CLOSURE and closure_ids
        if closure and msg.part == 0:
            current = []
        for k in msg.keys:
            before = annotation.get(k.id)
            if closure and before is not None and near(k.id):
                current.append((before.bound_m, k.bound_m, before.level != k.level))
            annotation[k.id] = k
        if closure and msg.part + 1 == msg.parts:
            if current:
                ratios = [after / before for before, after, _ in current if before > 0]
                rows.append({
                    "closure_key_poses": sorted(set(closure_ids)), "near": len(current),
                    "lowered": sum(after < before for before, after, _ in current),
                    "bound_before_mm": 1e3 * statistics.median(b for b, _, _ in current),
                    "bound_after_mm": 1e3 * statistics.median(a for _, a, _ in current),
                    "ratio_median": statistics.median(ratios), "ratio_min": min(ratios),
                    "level_changed": sum(c for _, _, c in current)})
            closure_ids = []
    for r in rows:
        print(f"closure {r['closure_key_poses']}: {r['near']} key poses within {args.near_m:g} m, "
              f"{r['lowered']} lower; median bound {r['bound_before_mm']:.1f} -> "
              f"{r['bound_after_mm']:.1f} mm (ratio median {r['ratio_median']:.3f}, smallest "
              f"{r['ratio_min']:.3f}); level changed: {r['level_changed']}")
    print(json.dumps(rows))


if __name__ == "__main__":
    main()
