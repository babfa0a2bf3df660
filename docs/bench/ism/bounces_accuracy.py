#!/usr/bin/env python3
"""ISM with 1, 2, 3 bounces against the path-traced reference with the same bounces
(gi-reference --quantity direct+indirect --bounces K --no-emitter-light: the VPLs come from
the scene's lights only, so emissive surfaces such as the Cornell box's lamp quad are seen but
light nothing in the reference either): NRMSE of the lit image, and the frame
time (gi-render --timings: median frame; R interleaved repetitions, median [min, max]).

usage: bounces_accuracy.py OUT.md REPS SCENE WxH SPP 'label=BIN [--set ...]' ...
NRMSE = RMS(lit - reference) / mean(reference) over geometry pixels, leaving out emitter
pixels (reference above 20x the median: the light panel would dominate the sum, as gi-bench's
--exclude-emitters does). For K > 1 also the light the later bounces add (K bounces minus 1
bounce, in the renderer and in the reference): its mean against the reference's ("energy")
and its NRMSE.
"""
import os, re, statistics, subprocess, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pfm import read_pfm  # noqa: E402

out, reps, scene, size, spp = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5]
w, h = size.split("x")
configs = [(a.split("=", 1)[0], a.split("=", 1)[1].split()) for a in sys.argv[6:]]
tmp = tempfile.mkdtemp()
ref_bin = os.path.join(os.path.dirname(configs[-1][1][0]), "gi-reference")
rows = []
first = {}  # K = 1: the reference's and each configuration's grey values, per pixel
for k in (1, 2, 3):
    ref = f"{tmp}/ref{k}.pfm"
    subprocess.run([ref_bin, "--scene", scene, "--quantity", "direct+indirect", "--bounces", str(k), "--no-emitter-light",
                    "--spp", spp, "--width", w, "--height", h, "--out", ref, "--gbuffer", f"{tmp}/g{k}"],
                   check=True, capture_output=True)
    _, _, n, rv = read_pfm(ref)
    mask_pfm = read_pfm(f"{tmp}/g{k}_depth.pfm") if os.path.exists(f"{tmp}/g{k}_depth.pfm") else None
    lum = [sum(rv[i * n:(i + 1) * n]) / n for i in range(len(rv) // n)]
    geo = [i for i in range(len(lum)) if mask_pfm is None or mask_pfm[3][i * mask_pfm[2] + 2] > 0.5]
    med = statistics.median(lum[i] for i in geo)
    keep = [i for i in geo if lum[i] <= 20 * med] if k == 1 else first["keep"]
    grey = lambda v, c, i: sum(v[i * c:i * c + 3]) / 3
    R = {i: grey(rv, n, i) for i in keep}
    if k == 1:
        first["keep"], first["ref"] = keep, R
    times = {label: [] for label, _ in configs}
    nrmse = {}
    for r in range(reps):
        for label, cmd in configs:
            img = f"{tmp}/{label}{k}.pfm"
            res = subprocess.run(cmd + ["--scene", scene, "--effects", "ism", "--width", w, "--height", h,
                                        "--frames", "3", "--timings", "--view", "lit", "--out", img,
                                        "--set", f"ism.bounces={k}"], capture_output=True, text=True, check=True)
            total = [float(m.group(1)) for m in re.finditer(r"^total\s+([0-9.]+)$", res.stdout, re.M)]
            times[label].append(total[0])
            if r == 0:
                _, _, m, sv = read_pfm(img)
                S = {i: grey(sv, m, i) for i in keep}
                se = sum((S[i] - R[i]) ** 2 for i in keep)
                mean = sum(R.values()) / len(keep)
                nrmse[label] = [(se / len(keep)) ** 0.5 / mean, None, None]
                if k == 1:
                    first[label] = S
                else:
                    dS = {i: S[i] - first[label][i] for i in keep}
                    dR = {i: R[i] - first["ref"][i] for i in keep}
                    mR = sum(dR.values()) / len(keep)
                    nrmse[label][1] = sum(dS.values()) / len(keep) / mR
                    nrmse[label][2] = (sum((dS[i] - dR[i]) ** 2 for i in keep) / len(keep)) ** 0.5 / mR
    for label, _ in configs:
        t = times[label]
        rows.append((k, label, nrmse[label], statistics.median(t), min(t), max(t)))
    print(k, nrmse, flush=True)
with open(out, "w") as f:
    f.write(f"scene {scene}, {size}, reference {spp} spp with the same bounces; {reps} interleaved repetitions of 3 frames; "
            f"load average now {os.getloadavg()[0]:.1f}\n\n")
    f.write("| bounces | configuration | NRMSE vs reference | light of bounces 2..K: mean / reference's | its NRMSE | frame ms, median [min, max] |\n|---|---|---:|---:|---:|---:|\n")
    fmt = lambda v: "-" if v is None else f"{v:.3f}"
    for k, label, e, t, lo, hi in rows:
        f.write(f"| {k} | {label} | {e[0]:.4f} | {fmt(e[1])} | {fmt(e[2])} | {t:.1f} [{lo:.1f}, {hi:.1f}] |\n")
    f.write("\ncommands: " + "; ".join(f"{l} = {' '.join(c)}" for l, c in configs) + "\n")
print(open(out).read())
