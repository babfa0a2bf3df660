#!/usr/bin/env bash
# Seed 000 Table 1 on this device: SSAO vs SSDO vs SSDO + 1 bounce at N = 8 and 16 samples,
# per resolution, as paired ratios over SSAO (docs/bench/ssdo/README.md, "Table 1").
#   docs/bench/ssdo/table1.sh [--reps R] [--frames F] [--scene S] [--sizes WxH,WxH]
#                             [--out DIR] [BUILD]
# One gi-bench run per size; in it the six configurations (SSAO, SSDO, SSDO + bounce at N = 8
# and 16; `layers` 1 as in the paper's table, every other setting at its default) are interleaved repetition by repetition, so a
# repetition's ratio to SSAO compares measurements taken back to back. Scores are not used
# here (the reference is 1 sample per pixel: only the times count), so of gi-bench's output
# only results.json is kept, as DIR/<size>.json (every repetition's pass times); DIR/table1.csv
# and the printed table come from them (summarize.py table1).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../../.."
reps=9 frames=2 scene=default sizes=320x240,640x480,800x600 out=docs/bench/ssdo/table1
while [[ $# -gt 0 && $1 == --* ]]; do
  case $1 in
  --reps) reps=$2 ;;
  --frames) frames=$2 ;;
  --scene) scene=$2 ;;
  --sizes) sizes=$2 ;;
  --out) out=$2 ;;
  *) echo "table1.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift 2
done
build=${1:-build}
bench=$build/bin/gi-bench
[[ -x $bench ]] || { echo "table1.sh: no $bench" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
IFS=, read -ra size_list <<<"$sizes"
dirs=()
for size in "${size_list[@]}"; do
  [[ $size =~ ^([0-9]+)x([0-9]+)$ ]] || { echo "table1.sh: bad size $size" >&2; exit 2; }
  echo "== $size: $(uptime)" >&2
  "$bench" --scenes "$scene" --effects ssao,ssdo --presets none \
    --grid ssao.samples=8,16 --grid ssdo.samples=8,16 --grid ssdo.bounce=false,true --grid ssdo.layers=1 \
    --width "${BASH_REMATCH[1]}" --height "${BASH_REMATCH[2]}" --frames "$frames" --reps "$reps" \
    --ref-spp 1 --cache "$tmp/cache" --no-progress --out "$tmp/$size" >&2
  mkdir -p "$out"
  cp "$tmp/$size/results.json" "$out/$size.json"
  dirs+=("$out/$size.json")
done
echo "== done: $(uptime)" >&2
python3 docs/bench/ssdo/summarize.py table1 "$out/table1.csv" "${dirs[@]}"
