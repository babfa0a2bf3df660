#!/usr/bin/env python3
"""Runs every command of README.md's ```sh blocks, as written but at a small size.

usage: readme_examples.py SOURCE_DIR BUILD_DIR [--list]      (ctest: readme_examples)

Each command runs with bash in a fresh folder holding `assets` and `build` (links to the source
tree's assets and the build tree), so the README's relative paths (assets/..., build/bin/...,
out/...) mean what they say and nothing is written into the checkout. "At a small size":
images 96x72, 2 frames, 4 samples per pixel for references, 2 repetitions per gi-bench
configuration, frame budgets x20 in a sanitized build; a window (gi-render --window, gi-demo without a script) opens under Xvfb for 2
frames. Everything else is the README's text: flags, scenes, presets, chained files (the
calibrated preset the next line renders with). Other commands (cmake --install) run as written. The
set-up commands (tools/demo, tools/test) are not run: they are what runs this. A command fails the test when it exits non-zero, or when an
output it names (--out, --png, --graph-dot, a script's screenshots) is missing afterwards.
"""
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time

APPS = ("gi-render", "gi-demo", "gi-reference", "gi-bench")
SIZE = ("96", "72")
SETUP = ("tools/demo", "tools/test")


def commands(readme):
    """(line number, command) for each command of the ```sh blocks, continuations joined."""
    out, block, pending, start = [], False, "", 0
    for n, line in enumerate(open(readme, encoding="utf-8"), 1):
        line = line.rstrip("\n")
        if line.startswith("```"):
            block = line.strip() == "```sh"
            continue
        if not block:
            continue
        if not pending:
            start = n
        if line.endswith("\\"):
            pending += line[:-1]
            continue
        text = (pending + line).strip()
        pending = ""
        text = re.sub(r"\s+#.*$", "", text)  # a trailing comment
        if text and not text.startswith("#"):
            out.append((start, text))
    return out


def app_of(words):
    for w in words:
        base = os.path.basename(w)
        if base in APPS and "/bin/" in w:
            return base
    return None


def set_flag(words, flag, value, append=True):
    if flag in words:
        i = words.index(flag)
        words[i + 1] = value
    elif append:
        words += [flag, value]


def small(text, slowdown=1.0):
    """The command at a small size (other commands, e.g. cmake --install, as written).
    `slowdown`: how much slower this build runs than a release build (budgets scale with it)."""
    words = shlex.split(text)
    app = app_of(words)
    if app is None:
        return words
    if "--list-effects" in words:
        return words
    set_flag(words, "--width", SIZE[0])
    set_flag(words, "--height", SIZE[1])
    set_flag(words, "--frames", "2", append=app in ("gi-bench",) or "--window" in words or
             (app == "gi-demo" and "--script" not in words))
    set_flag(words, "--spp", "4", append=False)
    if app == "gi-bench" and "--hard-cases" not in words:
        set_flag(words, "--ref-spp", "4")
        set_flag(words, "--reps", "2")
    if "--budget-ms" in words:
        i = words.index("--budget-ms") + 1
        words[i] = f"{float(words[i]) * slowdown:g}"
    windowed = "--window" in words or (app == "gi-demo")
    if windowed and words[0] != "xvfb-run":
        words = ["xvfb-run", "-a", "-s", "-screen 0 640x480x24"] + words
    return words


def outputs(words, cwd):
    """Files and folders the command says it writes."""
    named = []
    for flag in ("--out", "--png", "--graph-dot"):
        if flag in words:
            named.append(words[words.index(flag) + 1])
    if "--script" in words:
        script = os.path.join(cwd, words[words.index("--script") + 1])
        for line in open(script, encoding="utf-8"):
            parts = line.split("#")[0].split()
            if parts[:1] == ["screenshot"]:
                named.append(parts[1])
    return named


def main():
    src, build = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    cmds = commands(os.path.join(src, "README.md"))
    if "--list" in sys.argv:
        for n, c in cmds:
            print(f"README.md:{n}: {c}")
        return 0
    failures, ran, written = [], 0, {}
    # A sanitized build (the asan preset) runs the GPU passes ~10-20x slower on a CPU driver:
    # frame budgets (gi-bench --calibrate) scale with it, so the example means the same there.
    cache = open(os.path.join(build, "CMakeCache.txt"), encoding="utf-8").read()
    slowdown = 20.0 if re.search(r"^GI_SANITIZE:BOOL=ON$", cache, re.M) else 1.0
    with tempfile.TemporaryDirectory(prefix="gi-readme-") as cwd:
        os.symlink(os.path.join(src, "assets"), os.path.join(cwd, "assets"))
        os.symlink(build, os.path.join(cwd, "build"))
        env = dict(os.environ, GI_VALIDATION="1")
        for n, text in cmds:
            if text.split()[0] in SETUP:
                print(f"README.md:{n}: set-up command, not run here: {text}")
                continue
            words = small(text, slowdown)
            began = time.monotonic()
            r = subprocess.run(words, cwd=cwd, env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, timeout=900)
            seconds = time.monotonic() - began
            ran += 1
            shown = " ".join(shlex.quote(w) for w in words)
            print(f"README.md:{n}: exit {r.returncode} in {seconds:.1f} s: {shown}")
            for o in outputs(words, cwd):  # two examples writing one file confuse a reader
                if o in written:
                    failures.append(f"README.md:{n}: writes {o} as README.md:{written[o]} does")
                written[o] = n
            missing = [o for o in outputs(words, cwd) if not os.path.exists(os.path.join(cwd, o))]
            bad = [l for l in r.stdout.splitlines() if "Validation Error" in l or "VUID-" in l]
            if r.returncode != 0 or missing or bad:
                print(r.stdout[-4000:])
                why = f"exit {r.returncode}" if r.returncode else \
                    f"missing outputs {missing}" if missing else "validation errors"
                failures.append(f"README.md:{n}: {why}: {text}")
    print(f"{ran} README commands run, {len(failures)} failed")
    for f in failures:
        print("FAILED " + f)
    return 1 if failures or ran < 20 else 0


if __name__ == "__main__":
    sys.exit(main())
