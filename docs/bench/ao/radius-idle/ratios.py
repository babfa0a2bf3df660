#!/usr/bin/env python3
"""Cost against the radius, paired repetition by repetition: for each effect the ratio of its
time at each radius to its time at the smallest radius in the same repetition (gi-bench
interleaves configurations round-robin, so a repetition's values were measured back to back).
Prints a markdown table: median ratio [min, max] over the repetitions.
Usage: ratios.py repetitions.csv"""
import csv
import statistics
import sys
from collections import defaultdict

rows = list(csv.DictReader(open(sys.argv[1])))
times = defaultdict(dict)  # (effect, radius) -> {rep: effect_ms}
for r in rows:
    radius = float(r["params"].split("=")[1])
    times[(r["effect"], radius)][int(r["rep"])] = float(r["effect_ms"])
print("| effect | radius | effect ms, median [min, max] | x radius 0.125, median [min, max] |")
print("|---|---:|---:|---:|")
for effect in dict.fromkeys(e for e, _ in times):
    radii = sorted(r for e, r in times if e == effect)
    base = times[(effect, radii[0])]
    for radius in radii:
        t = times[(effect, radius)]
        ratios = [t[k] / base[k] for k in t if k in base]
        v = list(t.values())
        print(f"| {effect} | {radius:g} | {statistics.median(v):.2f} [{min(v):.2f}, {max(v):.2f}] | "
              f"{statistics.median(ratios):.3f} [{min(ratios):.3f}, {max(ratios):.3f}] |")
