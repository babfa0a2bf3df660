#!/usr/bin/env python3
"""Seed 002 Fig. 4's shape: the ISM's error against classic shadow maps of the same resolution
for the same VPLs, while varying the points per ISM and the ISM resolution. Both modes share
the VPLs (the same RSM and sampling); only the visibility maps differ, so the NRMSE of the
indirect light (gi-render --view indirect) isolates what imperfect maps cost.

usage: fig4_classic.py OUT.md SCENE WxH VPLS BIN_DIR [RES,RES,...] [POINTS,POINTS,...] [ISM_SET,...]
                       [REFERENCE_RES]
(ISM_SET: extra --set of the ISM runs only, e.g. ism.pull_push_levels=0, or "-" for none;
REFERENCE_RES: the classic maps' resolution for every row, instead of each row's own)
NRMSE = RMS(ism - classic) / mean(classic) over the geometry pixels (gi-render --view depth).
"""
import os, subprocess, sys, tempfile, time


sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pfm import read_pfm  # noqa: E402


out, scene, size, vpls, bindir = sys.argv[1:6]
resolutions = [int(r) for r in (sys.argv[6] if len(sys.argv) > 6 else "32,64,128").split(",")]
points = [int(p) for p in (sys.argv[7] if len(sys.argv) > 7 else "256,1024,4096,16384").split(",")]
extra = sys.argv[8].split(",") if len(sys.argv) > 8 and sys.argv[8] != "-" else []
reference_res = int(sys.argv[9]) if len(sys.argv) > 9 else 0
w, h = size.split("x")
tmp = tempfile.mkdtemp()
render = os.path.join(bindir, "gi-render")


def run(name, sets, view="indirect"):
    path = f"{tmp}/{name}.pfm"
    argv = [render, "--scene", scene, "--effects", "ism", "--width", w, "--height", h, "--view",
            view, "--out", path, "--set", f"ism.vpls={vpls}"]
    for s in sets:
        argv += ["--set", s]
    start = time.time()
    subprocess.run(argv, check=True, capture_output=True)
    _, _, n, values = read_pfm(path)
    return (n, values), time.time() - start


(n_depth, depth), _ = run("depth", [], "depth")
geometry = [depth[i * n_depth] > 0.0 for i in range(len(depth) // n_depth)]

rows = []
for res in resolutions:
    cres = reference_res or res
    (n, classic), t_classic = run(f"classic{cres}", [f"ism.ism_resolution={cres}", "ism.mode=classic"])
    ref = [sum(classic[i * n: i * n + 3]) / 3 for i in range(len(geometry))]
    mean = sum(v for v, g in zip(ref, geometry) if g) / max(sum(geometry), 1)
    cells = []
    for p in points:
        (n, ism), t = run(f"ism{res}_{p}", [f"ism.ism_resolution={res}", f"ism.points_per_ism={p}"] + extra)
        err = [sum(ism[i * n: i * n + 3]) / 3 - ref[i] for i in range(len(geometry))]
        mse = sum(e * e for e, g in zip(err, geometry) if g) / max(sum(geometry), 1)
        cells.append(mse ** 0.5 / mean if mean > 0 else float("nan"))
        print(f"res {res} points {p}: NRMSE {cells[-1]:.4f}", flush=True)
    rows.append((res, cells))

with open(out, "w") as f:
    f.write(f"# ISM against classic maps of the same resolution (seed 002 Fig. 4 shape)\n\n")
    against = f"{reference_res}^2 classic maps" if reference_res else "classic maps of the same resolution"
    f.write(f"Scene `{scene}`, {size}, {vpls} VPLs; NRMSE of the indirect light against {against} "
            f"(same VPLs), geometry pixels. Command: `python3 {' '.join(sys.argv)}`\n\n")
    f.write("| ISM resolution | " + " | ".join(f"{p} points" for p in points) + " |\n")
    f.write("|---:|" + "---:|" * len(points) + "\n")
    for res, cells in rows:
        f.write(f"| {res} | " + " | ".join(f"{c:.4f}" for c in cells) + " |\n")
print("wrote", out)
