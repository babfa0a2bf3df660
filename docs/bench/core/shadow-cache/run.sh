#!/usr/bin/env bash
# Shadow maps that cost only what changed (engine.shadow_cache): every map drawn whole each
# frame ("off") against the cached static casters ("on"), the same build, interleaved rounds,
# per-pass process CPU time with each pass submitted alone. Writes the tables beside this file.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../../../.."
here=docs/bench/core/shadow-cache
rounds=${ROUNDS:-7}
ab=(off="--set engine.shadow_cache=false" on="")
# The demo courtyard with its clock running: characters walk, and the sun, the spot and the
# point light move every frame too.
tools/bench-variants --rounds "$rounds" --frames 10 --scenes assets/scenes/demo.json \
  --sizes 320x180 --common "--preset lavapipe --time 5 --time-step 0.0333" \
  --out $here/demo-animated.md "${ab[@]}"
# The same courtyard with its clock stopped (what the lights see does not change; the skinned
# characters are still drawn every frame, as they are dynamic casters).
tools/bench-variants --rounds "$rounds" --frames 10 --scenes assets/scenes/demo.json \
  --sizes 320x180 --common "--preset lavapipe --time 5" --out $here/demo-still.md "${ab[@]}"
# Characters animating under still lights (the crowd's sun; animated.json's sun, its spot orbits).
tools/bench-variants --rounds "$rounds" --frames 10 \
  --scenes assets/scenes/animated.json,assets/scenes/skinning_crowd.json --sizes 320x180 \
  --common "--time 1 --time-step 0.0333" --out $here/characters.md "${ab[@]}"
# Still scenes at 1280x720: the room and the 69k-triangle bunny (the core frame of issue 29).
tools/bench-variants --rounds "$rounds" --frames 10 \
  --scenes default,assets/scenes/bunny_on_plane.json --sizes 1280x720 --common "--effects none" \
  --out $here/still-1280x720.md "${ab[@]}"
