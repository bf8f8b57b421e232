#!/usr/bin/python3
"""scripts/carry_relations.py on two crafted logs of the same scans: the second keeps every other
scan of the first, under stamps 100 s earlier, prints its ranges with other digits ("1.5" for
"1.50") and starts with a scan the first does not hold. Relations between kept scans must come
out under the second log's stamps, the rest be left out, and a log of other scans carry none.

    carry_relations_test.py
"""
import gzip
import json
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "..", "scripts", "carry_relations.py")


def flaser(ranges, stamp, short):
    text = " ".join(f"{r:g}" if short else f"{r:.2f}" for r in ranges)
    return f"FLASER {len(ranges)} {text} 0 0 0 0 0 0 {stamp} host {stamp}\n"


def scan(i):
    """Scan i's ranges: distinct for every i."""
    return [1.0 + 0.01 * ((i * 7 + k * 3) % 97) for k in range(8)]


class CarryRelations(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        self.full = os.path.join(self.dir, "full.log.gz")
        with gzip.open(self.full, "wt") as f:
            for i in range(10):
                f.write(f"ODOM 0 0 0 0 0 0 {1000.0 + i - 0.5:.6f} host 0\n")
                f.write(flaser(scan(i), f"{1000.0 + i:.6f}", False))
        self.relations = os.path.join(self.dir, "full.relations")
        with open(self.relations, "w") as f:
            f.write("1000.000000 1002.000000 0.5 0.1 0 0 0 0.01\n")   # both kept
            f.write("1002.000000 1003.000000 0.4 0.0 0 0 0 0.02\n")   # 1003 not kept
            f.write("1008.000000 1004.000000 -1.2 0.3 0 0 0 -0.03\n")  # both kept
        self.part = os.path.join(self.dir, "part.log")
        with open(self.part, "w") as f:
            f.write(flaser([9.0] * 8, "899.5", True))  # a scan the full log does not hold
            for i in range(0, 10, 2):
                f.write(flaser(scan(i), f"{900.0 + i:g}", True))

    def run_script(self, other):
        out = os.path.join(self.dir, "carried.relations")
        p = subprocess.run([sys.executable, SCRIPT, self.relations, self.full, other, "--out", out],
                           capture_output=True, text=True)
        summary = json.loads(p.stderr.strip().splitlines()[0])
        lines = []
        if os.path.exists(out):
            with open(out) as f:
                lines = [line for line in f.read().split("\n") if line]
        return p.returncode, summary, lines

    def test_relations_between_kept_scans_come_out_under_the_other_stamps(self):
        rc, summary, lines = self.run_script(self.part)
        self.assertEqual(rc, 0)
        self.assertEqual(summary["scans_tied"], 5)
        self.assertEqual(summary["other_log_scans"], 6)
        self.assertEqual(summary["relations_carried"], 2)
        self.assertEqual(lines[0].split(), ["900", "902", "0.5", "0.1", "0", "0", "0", "0.01"])
        self.assertEqual(lines[1].split()[:2], ["908", "904"])
        self.assertEqual(lines[1].split()[7], "-0.03")

    def test_a_log_of_other_scans_carries_nothing_and_fails(self):
        other = os.path.join(self.dir, "other.log")
        with open(other, "w") as f:
            for i in range(5):
                f.write(flaser([5.0 + i] * 8, f"{i}.0", False))
        rc, summary, lines = self.run_script(other)
        self.assertNotEqual(rc, 0)
        self.assertEqual(summary["relations_carried"], 0)
        self.assertEqual(lines, [])


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
