#!/usr/bin/env python3
"""Old vs new ISM binaries, interleaved: per-pass GPU timestamps (gi-render --timings
--isolate-passes), R repetitions of each configuration in turn; prints medians [min, max]
over the repetitions of each pass's median over the frames, and the load average.

usage: compare.py OUT.md REPS FRAMES WxH SCENE 'label=BIN [--set ...]' ...
"""
import os, re, statistics, subprocess, sys

out, reps, frames, size, scene = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5]
w, h = size.split("x")
configs = []
for arg in sys.argv[6:]:
    label, cmd = arg.split("=", 1)
    configs.append((label, cmd.split()))
times = {label: {} for label, _ in configs}
loads = []
for r in range(reps):
    for label, cmd in configs:
        loads.append(os.getloadavg()[0])
        argv = [cmd[0], "--scene", scene, "--effects", "ism", "--width", w, "--height", h,
                "--frames", frames, "--timings", "--isolate-passes", "--out",
                f"/tmp/ism-speed-{label}.png"] + cmd[1:]
        res = subprocess.run(argv, capture_output=True, text=True, timeout=900)
        if res.returncode != 0:
            sys.exit(f"{label}: {res.stderr}")
        for line in res.stdout.splitlines():
            m = re.match(r"^(\S+)\s+([0-9.]+)$", line)
            if m:
                times[label].setdefault(m.group(1), []).append(float(m.group(2)))
        print(label, r, times[label].get("total", [None])[-1], flush=True)
passes = []
for label, _ in configs:
    for p in times[label]:
        if p not in passes:
            passes.append(p)
gi = ["ism_rsm", "ism_vpl", "ism_clear", "ism_splat", "ism_pull_push", "ism_gather", "ism_blur"]
def cell(v):
    if not v:
        return "-"
    return f"{statistics.median(v):.1f} [{min(v):.1f}, {max(v):.1f}]"
lines = [f"scene {scene}, {size}, {frames} frames per run, {reps} interleaved repetitions; "
         f"load average (1 min) at the runs' starts: median {statistics.median(loads):.1f} "
         f"[{min(loads):.1f}, {max(loads):.1f}]", "",
         "| pass (ms, median [min, max] over repetitions) | " + " | ".join(l for l, _ in configs) + " |",
         "|---|" + "---:|" * len(configs)]
for p in passes:
    lines.append(f"| {p} | " + " | ".join(cell(times[l].get(p)) for l, _ in configs) + " |")
sums = []
for l, _ in configs:
    per_rep = [sum(times[l][p][i] for p in gi if p in times[l]) for i in range(reps)]
    sums.append(cell(per_rep))
lines.append("| **GI stages** (" + "+".join(gi) + ") | " + " | ".join(sums) + " |")
lines.append("")
lines.append("commands: " + "; ".join(f"{l} = {' '.join(c)}" for l, c in configs))
open(out, "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
