#!/usr/bin/env python3
"""Markdown tables for docs/study.md from the sweeps' sweep.csv files: for each value of the
swept key, the mean and sample standard deviation over the seeds of the study's metrics.

    python3 docs/study/table.py out/study/fiber_length/sweep.csv ...
"""
import csv
import statistics
import sys

METRICS = ("separation_roughness", "peeled_area", "peak_grip_force", "splits_interlayer", "pieces")
FIXED = {"index", "seed", "status", "error", "digest", "steps"}


def swept_key(header):
    """The first column that is a scene key (dotted) rather than a metric."""
    return next(h for h in header if "." in h and h not in FIXED)


def table(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["status"] == "completed"]
    key = swept_key(list(rows[0].keys()))
    values = []
    for r in rows:
        if r[key] not in values:
            values.append(r[key])
    lines = [f"`{key}` ({len(rows)} runs)", "",
             "| " + key.split(".")[-1] + " | " + " | ".join(METRICS) + " |",
             "| --- |" + " --- |" * len(METRICS)]
    for v in values:
        group = [r for r in rows if r[key] == v]
        cells = []
        for m in METRICS:
            xs = [float(r[m]) for r in group]
            sd = statistics.stdev(xs) if len(xs) > 1 else 0.0
            cells.append(f"{statistics.mean(xs):.3g} ± {sd:.2g}")
        lines.append(f"| {v} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    print("\n\n".join(table(p) for p in sys.argv[1:]))
