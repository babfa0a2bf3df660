#!/usr/bin/env python3
"""Compares the first channel of two PFM images (standard library only).

usage: compare_pfm.py A.pfm B.pfm TOLERANCE
Exits 0 when both have the same size, at least a tenth of the pixels are geometry (> 0) in A,
and |A - B| <= TOLERANCE everywhere; prints the largest difference either way.
"""
import struct
import sys


def read_pfm(path):
    data = open(path, "rb").read()
    parts = data.split(b"\n", 3)
    if parts[0].strip() not in (b"PF", b"Pf"):
        sys.exit(f"{path}: not a PFM")
    channels = 3 if parts[0].strip() == b"PF" else 1
    width, height = map(int, parts[1].split())
    little = float(parts[2]) < 0
    count = width * height * channels
    values = struct.unpack(("<" if little else ">") + "f" * count, parts[3][:count * 4])
    return width, height, values[::channels]


wa, ha, a = read_pfm(sys.argv[1])
wb, hb, b = read_pfm(sys.argv[2])
tolerance = float(sys.argv[3])
if (wa, ha) != (wb, hb):
    sys.exit(f"sizes differ: {wa}x{ha} vs {wb}x{hb}")
worst = max(abs(x - y) for x, y in zip(a, b))
geometry = sum(1 for x in a if x > 0.0)
print(f"{wa}x{ha}: largest difference {worst:.3g}, geometry pixels {geometry}")
sys.exit(0 if worst <= tolerance and geometry * 10 >= len(a) else 1)
