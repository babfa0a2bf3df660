#!/usr/bin/env python3
"""Tables from gi-bench's results.json for docs/bench/ssdo (table1.sh, accuracy.sh).

  summarize.py table1 OUT.csv RESULTS...   SSAO / SSDO / SSDO + bounce per size and sample count
  summarize.py steps OUT.csv RESULTS...    the accuracy steps and SSAO's sweep per scene, and
                                           beside OUT.csv the step plot (OUT.svg)
RESULTS: gi-bench output folders (their results.json) or results.json files.

Ratios are paired: gi-bench measures the configurations of a run interleaved (repetition r of
every configuration back to back), and results.json keeps each repetition's value in that
order, so ratio r = value_r(config) / value_r(baseline) compares two measurements taken under
the same load. Medians come with gi-bench's distribution-free interval of the median
(apps/scoring/stats.cpp): [x_(k), x_(n+1-k)], the largest k reaching 95% coverage
(n < 6: [min, max]).
"""
import csv
import json
import math
import os
import sys


def median(v):
    s = sorted(v)
    n = len(s)
    if n == 0:
        return 0.0
    return s[n // 2] if n % 2 else (s[n // 2 - 1] + s[n // 2]) / 2


def interval(v, confidence=0.95):
    """(median, lo, hi, coverage) as gi::bench::medianInterval."""
    s = sorted(v)
    n = len(s)
    if n == 0:
        return (0.0, 0.0, 0.0, 0.0)

    def cdf(j):  # P(Binomial(n, 1/2) <= j)
        return sum(math.comb(n, i) for i in range(0, min(j, n) + 1)) / 2.0**n

    k = 1
    while 2 * (k + 1) <= n + 1 and 1.0 - 2.0 * cdf(k) >= confidence:
        k += 1
    cov = 1.0 - 2.0 * cdf(k - 1) if n > 1 else 0.0
    return (median(s), s[k - 1], s[n - k], cov)


def fmt(i, digits=1):
    m, lo, hi, _ = i
    return f"{m:.{digits}f} [{lo:.{digits}f}-{hi:.{digits}f}]"


def load(dirs):
    rows = []
    for d in dirs:
        with open(d if d.endswith(".json") else os.path.join(d, "results.json")) as f:
            j = json.load(f)
        for r in j["results"]:
            r["_dir"] = d
            rows.append(r)
    return rows


def params(r):
    return dict(kv.split("=", 1) for kv in r["params"].split()) if r["params"] else {}


def pass_values(r, prefix):
    """Per repetition: the sum of the passes whose name starts with `prefix`."""
    sums = None
    for p in r["passes"]:
        if p["pass"].startswith(prefix):
            v = p["interval"]["values"]
            sums = list(v) if sums is None else [a + b for a, b in zip(sums, v)]
    return sums or [0.0] * r["reps"]


def ratios(a, b):
    return [x / y for x, y in zip(a, b) if y > 0]


def table1(out, dirs):
    rows = load(dirs)
    groups = {}
    for r in rows:
        p = params(r)
        n = p.get("ssao.samples") or p.get("ssdo.samples")
        kind = "ssao" if r["effect"] == "ssao" else (
            "ssdo+bounce" if p.get("ssdo.bounce") == "true" else "ssdo")
        groups.setdefault((r["width"], r["height"], int(n)), {})[kind] = r
    lines = []
    print("| size | N | effect | effect passes ms | x SSAO (effect) | frame ms | x SSAO (frame) "
          "| passes (ms, medians) |")
    print("|---|---|---|---|---|---|---|---|")
    for (w, h, n), g in sorted(groups.items()):
        base = g["ssao"]
        for kind in ("ssao", "ssdo", "ssdo+bounce"):
            r = g[kind]
            eff, tot = r["effect_interval"]["values"], r["total_interval"]["values"]
            re = interval(ratios(eff, base["effect_interval"]["values"]))
            rt = interval(ratios(tot, base["total_interval"]["values"]))
            passes = ", ".join(f"{p['pass']} {p['ms']:.0f}" for p in r["passes"]
                               if p["pass"] not in ("floor",))
            print(f"| {w}x{h} | {n} | {kind} | {fmt(interval(eff))} | {fmt(re, 2)} | "
                  f"{fmt(interval(tot))} | {fmt(rt, 2)} | {passes} |")
            lines.append({"width": w, "height": h, "samples": n, "effect": kind,
                          "reps": r["reps"], "frames": r["frames"],
                          "effect_ms": interval(eff)[0], "effect_lo": interval(eff)[1],
                          "effect_hi": interval(eff)[2], "effect_x_ssao": re[0],
                          "effect_x_ssao_lo": re[1], "effect_x_ssao_hi": re[2],
                          "frame_ms": interval(tot)[0], "frame_lo": interval(tot)[1],
                          "frame_hi": interval(tot)[2], "frame_x_ssao": rt[0],
                          "frame_x_ssao_lo": rt[1], "frame_x_ssao_hi": rt[2],
                          "coverage": re[3], "passes": passes})
    write_csv(out, lines)


STEPS = [  # (label, effect, settings that must match; unspecified grid keys must be absent)
    ("none (engine: direct + unoccluded SH9 environment)", "none", {}),
    ("SSDO", "ssdo", {"ssdo.bounce": "false", "ssdo.layers": "1", "ssdo.cameras": "0"}),
    ("SSDO + bounce", "ssdo", {"ssdo.bounce": "true", "ssdo.layers": "1", "ssdo.cameras": "0"}),
    ("+ 2 layers", "ssdo", {"ssdo.bounce": "true", "ssdo.layers": "2", "ssdo.cameras": "0"}),
    ("+ 1 camera", "ssdo", {"ssdo.bounce": "true", "ssdo.layers": "2", "ssdo.cameras": "1"}),
]


def steps(out, dirs):
    rows = load(dirs)
    lines = []
    for scene in dict.fromkeys(r["scene"] for r in rows):
        sr = [r for r in rows if r["scene"] == scene]
        print(f"\n{scene} ({sr[0]['width']}x{sr[0]['height']}, {sr[0]['reps']} reps x "
              f"{sr[0]['frames']} frames; NRMSE of the lit image vs {sr[0]['reference']})\n")
        print("| step | effect passes ms | frame ms | NRMSE | SSIM |")
        print("|---|---|---|---|---|")
        picked = []
        for r in sorted((r for r in sr if r["effect"] == "ssao"),
                        key=lambda r: int(params(r).get("ssao.samples", 16))):
            picked.append((f"SSAO-modulated lighting, {params(r).get('ssao.samples', 16)} taps",
                           r))
        for label, effect, want in STEPS:
            for r in sr:
                if r["effect"] == effect and all(params(r).get(k) == v for k, v in want.items()):
                    picked.append((label, r))
        for label, r in picked:
            eff, tot = interval(r["effect_interval"]["values"]), interval(
                r["total_interval"]["values"])
            print(f"| {label} | {fmt(eff)} | {fmt(tot)} | {r['nrmse']:.4f} | {r['ssim']:.4f} |")
            lines.append({"scene": scene, "step": label, "params": r["params"],
                          "width": r["width"], "height": r["height"], "reps": r["reps"],
                          "frames": r["frames"], "effect_ms": eff[0], "effect_lo": eff[1],
                          "effect_hi": eff[2], "frame_ms": tot[0], "frame_lo": tot[1],
                          "frame_hi": tot[2], "coverage": eff[3], "nrmse": r["nrmse"],
                          "ssim": r["ssim"], "reference": r["reference"],
                          "reference_stderr": r["reference_stderr"]})
    write_csv(out, lines)
    with open(os.path.splitext(out)[0] + ".svg", "w") as f:
        f.write(step_plot(lines))


def step_plot(lines):
    """One panel per scene: NRMSE against effect time (median, interval as a bar); SSAO's tap
    sweep and SSDO's steps as two polylines, the engine alone as a dashed level. Both axes start
    at 0, so a difference shows at its true size against the error itself."""
    scenes = list(dict.fromkeys(line["scene"] for line in lines))
    pw, ph, ml, mt, mb = 330, 260, 60, 40, 60
    width = len(scenes) * (pw + ml + 20) + 20
    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{ph + mt + mb + 60}" '
         'font-family="sans-serif" font-size="11">',
         '<rect width="100%" height="100%" fill="white"/>']
    for si, scene in enumerate(scenes):
        sl = [line for line in lines if line["scene"] == scene]
        x0 = 20 + si * (pw + ml + 20) + ml
        tmax = max(line["effect_hi"] for line in sl) * 1.05 or 1.0
        errs = [line["nrmse"] for line in sl]
        lo, hi = 0.0, max(errs) * 1.1 or 1.0

        def X(t):
            return x0 + pw * t / tmax

        def Y(e):
            return mt + ph * (1 - (e - lo) / (hi - lo))

        name = os.path.splitext(os.path.basename(scene))[0]
        o.append(f'<text x="{x0}" y="22" font-size="13">{name}: NRMSE vs '
                 f'{sl[0]["reference"]}, {sl[0]["width"]}x{sl[0]["height"]}</text>')
        o.append(f'<rect x="{x0}" y="{mt}" width="{pw}" height="{ph}" fill="none" '
                 'stroke="black"/>')
        for k in range(6):
            t, e = tmax * k / 5, lo + (hi - lo) * k / 5
            o.append(f'<text x="{X(t):.1f}" y="{mt + ph + 14}" text-anchor="middle">{t:.0f}</text>')
            o.append(f'<line x1="{x0}" x2="{x0 + pw}" y1="{Y(e):.1f}" y2="{Y(e):.1f}" '
                     'stroke="#eee"/>')
            o.append(f'<text x="{x0 - 4}" y="{Y(e) + 4:.1f}" text-anchor="end">{e:.4f}</text>')
        o.append(f'<text x="{x0 + pw / 2}" y="{mt + ph + 30}" text-anchor="middle">effect GPU '
                 f'ms (median; bars: {100 * sl[0]["coverage"]:.1f}% interval)</text>')
        series = [("SSAO-modulated lighting (4..64 taps)", "#ff7f0e",
                   [line for line in sl if line["step"].startswith("SSAO")]),
                  ("SSDO steps", "#2ca02c",
                   [line for line in sl if not line["step"].startswith(("SSAO", "none"))])]
        for name_, colour, pts in series:
            o.append(f'<polyline fill="none" stroke="{colour}" stroke-width="1.5" points="' +
                     " ".join(f'{X(p["effect_ms"]):.1f},{Y(p["nrmse"]):.1f}' for p in pts) +
                     '"/>')
            for p in pts:
                x, y = X(p["effect_ms"]), Y(p["nrmse"])
                o.append(f'<path d="M{X(p["effect_lo"]):.1f} {y:.1f}H{X(p["effect_hi"]):.1f}" '
                         f'stroke="{colour}"/><circle cx="{x:.1f}" cy="{y:.1f}" r="3.5" '
                         f'fill="{colour}"><title>{p["step"]}: {p["effect_ms"]:.1f} ms '
                         f'[{p["effect_lo"]:.1f}, {p["effect_hi"]:.1f}], NRMSE '
                         f'{p["nrmse"]:.4f}</title></circle>')
                label = p["step"].replace("SSAO-modulated lighting, ", "")
                o.append(f'<text x="{x + 5:.1f}" y="{y - 5:.1f}" font-size="9" '
                         f'fill="{colour}">{label}</text>')
        for p in sl:
            if p["step"].startswith("none"):
                o.append(f'<line x1="{x0}" x2="{x0 + pw}" y1="{Y(p["nrmse"]):.1f}" '
                         f'y2="{Y(p["nrmse"]):.1f}" stroke="#777" stroke-dasharray="4 3"/>'
                         f'<text x="{x0 + pw - 4}" y="{Y(p["nrmse"]) - 4:.1f}" '
                         'text-anchor="end" fill="#777" font-size="9">engine alone</text>')
        if si == 0:
            for k, (name_, colour, _) in enumerate(series):
                y = mt + ph + 48 + 14 * k
                o.append(f'<line x1="{x0}" x2="{x0 + 20}" y1="{y}" y2="{y}" stroke="{colour}" '
                         f'stroke-width="2"/><text x="{x0 + 25}" y="{y + 4}">{name_}</text>')
    o.append("</svg>\n")
    return "\n".join(o)


def write_csv(out, lines):
    with open(out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(lines[0].keys()))
        w.writeheader()
        for line in lines:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in line.items()})


if __name__ == "__main__":
    if len(sys.argv) < 4 or sys.argv[1] not in ("table1", "steps"):
        sys.exit(__doc__)
    {"table1": table1, "steps": steps}[sys.argv[1]](sys.argv[2], sys.argv[3:])
