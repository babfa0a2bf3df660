#!/usr/bin/env bash
# SSDO's accuracy steps against the path-traced direct + one-bounce reference, with their time
# (docs/bench/ssdo/README.md, "Accuracy against time").
#   docs/bench/ssdo/accuracy.sh [--reps R] [--frames F] [--scenes A,B] [--size WxH]
#                               [--ref-spp N] [--exclude-emitters] [--out DIR] [BUILD]
# One gi-bench run per scene, every configuration of the scene interleaved repetition by
# repetition: the engine alone, SSAO-modulated lighting at 4..64 taps, and SSDO (defaults:
# 12 samples, blur 2) over bounce x layers x cameras (the steps SSDO, + bounce, + 2 layers,
# + 1 camera, and the other combinations). `--target direct+indirect` scores every lit image,
# SSAO's included, against gi-reference's direct + one diffuse bounce. Writes DIR/<scene>/
# (gi-bench's results and plots) and DIR/steps.csv, and prints the step tables
# (summarize.py steps). --exclude-emitters passes gi-bench's flag of that name: pixels within one
# pixel of an emissive surface are left out of the scores (default out: DIR-no-emitters).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../../.."
reps=9 frames=2 size=320x240 spp=1024 out= extra=()
scenes=default,assets/scenes/cornell_box.json,assets/scenes/bunny_on_plane.json
while [[ $# -gt 0 && $1 == --* ]]; do
  case $1 in
  --reps) reps=$2 ;;
  --frames) frames=$2 ;;
  --scenes) scenes=$2 ;;
  --size) size=$2 ;;
  --ref-spp) spp=$2 ;;
  --out) out=$2 ;;
  --exclude-emitters) extra=(--exclude-emitters); shift; continue ;;
  *) echo "accuracy.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift 2
done
[[ -n $out ]] || out=docs/bench/ssdo/accuracy${extra:+-no-emitters}
build=${1:-build}
bench=$build/bin/gi-bench
[[ -x $bench ]] || { echo "accuracy.sh: no $bench" >&2; exit 2; }
[[ $size =~ ^([0-9]+)x([0-9]+)$ ]] || { echo "accuracy.sh: bad size $size" >&2; exit 2; }
IFS=, read -ra scene_list <<<"$scenes"
dirs=()
for scene in "${scene_list[@]}"; do
  name=$(basename "$scene" .json)
  echo "== $scene: $(uptime)" >&2
  "$bench" --scenes "$scene" --effects none,ssao,ssdo --presets none --target direct+indirect \
    --grid ssao.samples=4,8,16,32,64 \
    --grid ssdo.bounce=false,true --grid ssdo.layers=1,2 --grid ssdo.cameras=0,1 \
    --width "${BASH_REMATCH[1]}" --height "${BASH_REMATCH[2]}" --frames "$frames" --reps "$reps" \
    --ref-spp "$spp" "${extra[@]}" --no-progress --out "$out/$name" >&2
  dirs+=("$out/$name")
done
echo "== done: $(uptime)" >&2
python3 docs/bench/ssdo/summarize.py steps "$out/steps.csv" "${dirs[@]}"
