#!/usr/bin/env bash
# Lit-image accuracy of the GI effects (issue: lit-image accuracy you can trust). Reproduces the
# tables of README.md here (lavapipe, 2 cores: about 10 minutes, most of it references). Run
# from the repository root after a release build.
set -euo pipefail
out=docs/bench/accuracy
bench=build/bin/gi-bench
scenes=default,assets/scenes/cornell_box.json,assets/scenes/bunny_on_plane.json
# Every preset, the engine alone and each GI effect (and GTAO, an AO effect, for contrast),
# scored against direct + one bounce; references refined until their noise is at most a
# quarter of the smallest error they score, up to 4096 samples.
"$bench" --scenes "$scenes" --effects none,gtao,ssdo,ism --presets all \
  --target direct+indirect --width 320 --height 240 --ref-spp 256 --ref-spp-max 4096 \
  --frames 2 --reps 3 --no-progress --out "$out/presets"
