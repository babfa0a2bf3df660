#!/usr/bin/env bash
# Before (the main build's binary, OLD) vs after (this tree), interleaved (compare.py).
# usage: docs/bench/ism/run_speed.sh OLD_BIN_DIR [REPS]
set -euo pipefail
OLD=${1:?usage: docs/bench/ism/run_speed.sh OLD_BIN_DIR [REPS]}
REPS=${2:-3}
NEW=${NEW:-build/bin}
D=docs/bench/ism
S="--set ism.vpls=256 --set ism.ism_resolution=256 --set ism.points_per_ism=8192"
# A. ISM creation vs classic maps, 256 VPLs at 256^2 (seed 002), bunny (69k triangles).
python3 $D/compare.py $D/speed_creation.md "$REPS" 5 320x240 assets/scenes/bunny_on_plane.json \
  "old=$OLD/gi-render $S" "new=$NEW/gi-render $S" "classic=$NEW/gi-render $S --set ism.mode=classic"
# B. The public implementation's settings at 1280x720.
T="--set ism.vpls=1024 --set ism.ism_resolution=64 --set ism.pull_push_levels=6 --set ism.block_size=4 --set ism.points_per_ism=34"
for scene in default assets/scenes/cornell_box.json; do
  name=$(basename "$scene" .json)
  python3 $D/compare.py $D/speed_target_$name.md "$REPS" 5 1280x720 "$scene" \
    "old=$OLD/gi-render $T" "new=$NEW/gi-render $T" "new_half=$NEW/gi-render $T --set ism.gather_scale=2"
done
