#!/usr/bin/env bash
# Overhead of SSDO's depth peeling and additional cameras over plain SSDO (seed 000 §4), on
# this device: docs/bench/ssdo/README.md.
#   docs/bench/ssdo/extensions.sh [--runs N] [--frames F] [--scene S] [--sizes WxH,WxH]
#                                 [--configs "SETS;SETS;..."] [BUILD]
# --configs replaces the configurations (the first is the baseline of the "x plain" ratios; each
# a comma-separated list of --set values), e.g. "ssdo.samples=12;ssdo.contact_shadows=true".
# Each run is one gi-render --timings --isolate-passes process (median GPU ms per pass over F
# frames); the configurations are interleaved run by run (run 1 of all, then run 2, ...) so that
# load drift on a shared machine hits all alike. Prints per configuration the median [min-max]
# over the runs of the SSDO passes' sum ("ssdo*") and of the frame total, and the median over
# runs of the ratio to plain SSDO of the same run.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../../.."
runs=5 frames=5 scene=default sizes=320x240,640x480 config_list=
while [[ $# -gt 0 && $1 == --* ]]; do
  case $1 in
  --runs) runs=$2 ;;
  --frames) frames=$2 ;;
  --scene) scene=$2 ;;
  --sizes) sizes=$2 ;;
  --configs) config_list=$2 ;;
  *) echo "extensions.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift 2
done
build=${1:-build}
render=$build/bin/gi-render
[[ -x $render ]] || { echo "extensions.sh: no $render" >&2; exit 2; }
configs=("ssdo.layers=1,ssdo.cameras=0" "ssdo.layers=2" "ssdo.cameras=1" "ssdo.cameras=2"
  "ssdo.cameras=4")
[[ -z $config_list ]] || IFS=';' read -ra configs <<<"$config_list"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
IFS=, read -ra size_list <<<"$sizes"
for size in "${size_list[@]}"; do
  [[ $size =~ ^([0-9]+)x([0-9]+)$ ]] || { echo "extensions.sh: bad size $size" >&2; exit 2; }
  w=${BASH_REMATCH[1]} h=${BASH_REMATCH[2]}
  : >"$tmp/samples"  # lines: config run effect-ms total-ms
  for ((r = 1; r <= runs; ++r)); do
    for i in "${!configs[@]}"; do
      sets=()
      IFS=, read -ra kv <<<"${configs[$i]}"
      for s in "${kv[@]}"; do sets+=(--set "$s"); done
      GI_PIPELINE_CACHE="$tmp/cache" "$render" --scene "$scene" --effects ssdo "${sets[@]}" \
        --width "$w" --height "$h" --frames "$frames" --timings --isolate-passes \
        --out "$tmp/out.png" >"$tmp/log" 2>&1 ||
        { echo "extensions.sh: gi-render failed (${configs[$i]})" >&2; cat "$tmp/log" >&2; exit 1; }
      awk -v i="$i" -v r="$r" '$1 ~ /^ssdo/ && $2 ~ /^[0-9.]+$/ { e += $2 }
        $1 == "total" { t = $2 } END { print i, r, e, t }' "$tmp/log" >>"$tmp/samples"
    done
  done
  echo "== $scene, ${w}x$h, $runs interleaved runs x $frames frames (ms: median [min-max])"
  printf '%-32s %-26s %-10s %-26s %s\n' configuration "ssdo passes" "x plain" "frame total" "x plain"
  awk -v n="${#configs[@]}" -v names="${configs[*]}" '
    function med(a, k,   i, j, t) {
      for (i = 2; i <= k; ++i) for (j = i; j > 1 && a[j - 1] > a[j]; --j) { t = a[j]; a[j] = a[j - 1]; a[j - 1] = t }
      return k % 2 ? a[(k + 1) / 2] : (a[k / 2] + a[k / 2 + 1]) / 2 }
    { e[$1, $2] = $3; t[$1, $2] = $4; if ($2 > runs) runs = $2 }
    END {
      split(names, nm, " ")
      for (c = 0; c < n; ++c) {
        delete a; delete b; delete ra; delete rb
        for (r = 1; r <= runs; ++r) {
          a[r] = e[c, r]; b[r] = t[c, r]
          ra[r] = e[0, r] > 0 ? e[c, r] / e[0, r] : 0; rb[r] = t[0, r] > 0 ? t[c, r] / t[0, r] : 0
        }
        me = med(a, runs); lo = a[1]; hi = a[runs]; mt = med(b, runs); tl = b[1]; th = b[runs]
        printf "%-32s %7.1f [%6.1f-%6.1f]    %5.2f      %7.1f [%6.1f-%6.1f]    %5.2f\n", nm[c + 1], me, lo, hi, med(ra, runs), mt, tl, th, med(rb, runs)
      }
    }' "$tmp/samples"
done
