#!/usr/bin/env bash
# GTAO at half resolution (gtao.downsample=2) and at full resolution against Alchemy at its
# cheapest settings, one interleaved gi-bench run per scene (9 configurations: one batch, so
# every pair shares its rounds), passes submitted alone, then paired at matched error.
# Usage: docs/bench/ao/gtao-half-vs-alchemy/run.sh [REPS [OUT]]   (41: ~3.5 min in all, idle)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../../../.."
reps=${1:-41}
out=${2:-docs/bench/ao/gtao-half-vs-alchemy}
for s in default:default bunny_on_plane:assets/scenes/bunny_on_plane.json; do
  name=${s%%:*} scene=${s#*:}
  build/bin/gi-bench --out "$out/$name" --isolate-passes --scenes "$scene" --effects alchemy,gtao \
    --presets none --grid alchemy.samples=2,3,4 --grid alchemy.blur_radius=2 --grid gtao.slices=1 \
    --grid gtao.steps=3,4,8 --grid gtao.downsample=1,2 --grid gtao.blur_radius=2 \
    --width 320 --height 240 --reps "$reps" --frames 3 --no-progress
  tools/bench-pairs matched "$out/$name" --slow alchemy --fast gtao --time median \
    > "$out/$name/matched.md"
done
