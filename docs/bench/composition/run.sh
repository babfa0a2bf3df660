#!/usr/bin/env bash
# Issue: effects that compose, ISMs on large scenes. Reproduces every table of README.md here
# (lavapipe, 2 cores: about 20 minutes). Run from the repository root after a release build.
set -euo pipefail
out=docs/bench/composition
bench=build/bin/gi-bench
scenes=assets/scenes/demo.json,assets/scenes/room_bunny.json,assets/scenes/cornell_box.json,assets/scenes/bunny_sky.json
common=(--target direct+indirect --width 320 --height 180 --ref-spp 512 --no-progress)
# 1. Every preset: the engine alone, single effects, the combinations, each preset's recommendation.
"$bench" --scenes "$scenes" --effects none,gtao,ism,gtao+ism,ssdo,recommended --presets all \
  --frames 2 --reps 3 "${common[@]}" --out "$out/presets"
# 2. SSDO's near field + ISM's far field (no environment VPLs: SSDO takes the sky).
"$bench" --scenes "$scenes" --effects ssdo,ism,ssdo+ism --presets high \
  --grid ism.environment_vpls=0 --frames 2 --reps 3 "${common[@]}" --out "$out/ssdo_ism"
# 3. ISM against classic maps with the same VPLs, every preset.
"$bench" --scenes "$scenes" --effects ism --presets all --grid ism.mode=ism,classic \
  --frames 1 --reps 1 "${common[@]}" --out "$out/ism_vs_classic"
# 4. Seed 002 Fig. 4 on demo.json: indirect light against classic maps of the same resolution.
python3 docs/bench/ism/fig4_classic.py "$out/fig4_demo.md" assets/scenes/demo.json 320x180 256 build/bin
