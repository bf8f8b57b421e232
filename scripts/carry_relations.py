#!/usr/bin/env python3
"""Kummerle relations carried over to another CARMEN log that holds the same scans.

    scripts/carry_relations.py RELATIONS RELATIONS_LOG OTHER_LOG [--out FILE]

RELATIONS names scans by RELATIONS_LOG's stamps (the ipc_timestamp after the odometry pose of a
FLASER line). OTHER_LOG is another copy of the same recording under other stamps, for example a
copy subsampled or retimed for another benchmark: the subsampled CARMEN freiburg-079 log holds
4,792 of the full-rate fr079 log's 4,934 scans, with the same ranges and stamps 1,211.29 s
earlier. Each scan of OTHER_LOG is tied to the scan of RELATIONS_LOG with the same ranges (to the
centimetre, as the logs print them), in order; each relation whose two scans are both in OTHER_LOG
is written with OTHER_LOG's stamps, the rest are left out. The relations are then the ground
truth of OTHER_LOG too, for scripts/eval-kummerle.sh --relations and traverse-evaluator
--relations (which checks the loop closures by them too).

Writes the relations to --out (default: standard output); the last line on standard error is
JSON: scans in each log, scans tied, ties that were ambiguous (the same ranges twice, taken in
order), relations read, carried, and the largest stamp offset seen [s].
"""
import argparse
import gzip
import json
import sys


def scans(path):
    """(stamp text, ranges key) of each FLASER line, in the file's order."""
    opener = gzip.open if path.endswith(".gz") else open
    out = []
    with opener(path, "rt", errors="replace") as f:
        for line in f:
            if not line.startswith("FLASER "):
                continue
            fields = line.split()
            n = int(fields[1])
            # FLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp host logger
            if len(fields) < n + 9:
                continue  # a truncated line: read up to the damage
            key = tuple(round(float(r) * 100.0) for r in fields[2:2 + n])
            out.append((fields[2 + n + 6], key))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("relations")
    ap.add_argument("relations_log")
    ap.add_argument("other_log")
    ap.add_argument("--out")
    a = ap.parse_args()

    source = scans(a.relations_log)
    other = scans(a.other_log)
    by_key = {}
    for i, (stamp, key) in enumerate(source):
        by_key.setdefault(key, []).append(i)
    # Tie in order: the first scan of the same ranges after the last one tied.
    tie = {}  # relations-log stamp -> other-log stamp
    last = -1
    ambiguous = 0
    largest_offset = 0.0
    for stamp, key in other:
        candidates = [i for i in by_key.get(key, []) if i > last]
        if not candidates:
            continue
        ambiguous += len(by_key[key]) > 1
        last = candidates[0]
        tie[source[last][0]] = stamp
        largest_offset = max(largest_offset, abs(float(source[last][0]) - float(stamp)))

    read = carried = 0
    lines = []
    with open(a.relations) as f:
        for line in f:
            fields = line.split()
            if len(fields) < 8:
                continue
            read += 1
            if fields[0] in tie and fields[1] in tie:
                carried += 1
                lines.append(" ".join([tie[fields[0]], tie[fields[1]]] + fields[2:]))
    text = "\n".join(lines) + ("\n" if lines else "")
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    summary = {"relations_log_scans": len(source), "other_log_scans": len(other),
               "scans_tied": len(tie), "ambiguous_ties": ambiguous, "relations_read": read,
               "relations_carried": carried, "largest_offset_s": round(largest_offset, 6)}
    print(json.dumps(summary), file=sys.stderr)
    if carried == 0:
        print("no relation could be carried over: are the logs of the same recording?",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
