#!/usr/bin/env bash
# Plugin development without touching the engine, end to end:
#   1. installs the build tree into a temporary prefix (cmake --install),
#   2. builds this folder's vignette effect and a fresh copy of the template
#      (tools/new-effect) out of tree against that prefix only (find_package(gi)),
#   3. runs the INSTALLED gi-render with GI_PLUGIN_PATH pointing at both builds: the effects
#      are listed with their settings and module paths, run with validation on, show up as
#      executed passes, and the vignette darkens the image corners;
#   4. runs the other installed apps from the prefix alone, on the installed scenes (their
#      models come with them) and presets: gi-reference scores the Cornell box, gi-bench
#      benchmarks the out-of-tree effects, gi-demo shows them (under Xvfb) with the shipped
#      script.
# usage: run_test.sh BUILD_DIR SOURCE_DIR      (ctest: external_effect)
set -euo pipefail
build="$(cd "$1" && pwd)"
src="$(cd "$2" && pwd)"
tmp="$(mktemp -d "${TMPDIR:-/tmp}/gi-external.XXXXXX")"
trap 'rm -rf "$tmp"' EXIT
start=$SECONDS
step() { echo "== [$((SECONDS - start))s] $*"; }
fail() {
  echo "FAILED: $*" >&2
  exit 1
}
# expect FILE PATTERN WHAT: grep -E PATTERN in FILE or fail showing the file.
expect() {
  if ! grep -qE -- "$2" "$1"; then
    cat "$1" >&2
    fail "$3 (no line matching '$2' in the output above)"
  fi
}

step "install $build -> $tmp/install"
cmake --install "$build" --prefix "$tmp/install" >"$tmp/install.log" || {
  cat "$tmp/install.log" >&2
  fail "cmake --install"
}
prefix="$tmp/install"
gi="$prefix/bin/gi-render"
[ -x "$gi" ] || fail "no installed gi-render at $gi"
[ -f "$prefix/share/gi/shaders/common.glsl" ] || fail "common.glsl not installed"
for app in gi-bench gi-reference gi-demo; do
  [ -x "$prefix/bin/$app" ] || fail "no installed $app"
done
for f in presets/medium.json scenes/demo.json scenes/cornell_box.json models/fox/glTF/Fox.gltf \
  models/fox/LICENSE.md scripts/tour.txt environments/small_sun.hdr; do
  [ -f "$prefix/share/gi/$f" ] || fail "share/gi/$f not installed"
done

configure_and_build() {  # SRC_DIR BUILD_DIR
  cmake -S "$1" -B "$2" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" >"$2.log" 2>&1 || {
    cat "$2.log" >&2
    fail "configuring $1 against $prefix"
  }
  # The package must come from the install, not from the build or source tree.
  expect "$2/CMakeCache.txt" "^gi_DIR:PATH=$prefix/" "gi package not found in $prefix"
  cmake --build "$2" -j2 >>"$2.log" 2>&1 || {
    cat "$2.log" >&2
    fail "building $1"
  }
}

step "new-effect ext_grey (from effects/_template)"
"$src/tools/new-effect" ext_grey "$tmp/ext_grey" >/dev/null
step "build tests/external_effect (vignette) and ext_grey against the installed package"
configure_and_build "$src/tests/external_effect" "$tmp/vignette-build"
configure_and_build "$tmp/ext_grey" "$tmp/ext_grey-build"
[ -f "$tmp/vignette-build/plugins/gi_effect_vignette.so" ] || fail "no vignette module built"
[ -f "$tmp/ext_grey-build/plugins/gi_effect_ext_grey.so" ] || fail "no ext_grey module built"
[ -f "$tmp/vignette-build/plugins/gi_effect_second_view.so" ] || fail "no second_view module built"

export GI_PLUGIN_PATH="$tmp/vignette-build/plugins:$tmp/ext_grey-build/plugins"
step "installed gi-render --list-effects"
"$gi" --list-effects >"$tmp/list.txt" 2>&1 || {
  cat "$tmp/list.txt" >&2
  fail "gi-render --list-effects"
}
cat "$tmp/list.txt"
expect "$tmp/list.txt" "^vignette 1\.0 - " "vignette not listed"
expect "$tmp/list.txt" "module: $tmp/vignette-build/plugins/gi_effect_vignette\.so$" \
  "vignette module path not listed"
expect "$tmp/list.txt" "stage: after lighting, reads: lit, writes: lit vignette, debug view: vignette" \
  "vignette stage/resources not listed"
expect "$tmp/list.txt" "vignette\.strength \(float, default 0\.8, range \[0, 1\], uniform only\)" \
  "vignette.strength setting not listed"
expect "$tmp/list.txt" "^ext_grey 0\.1 - " "ext_grey (copied template) not listed"
expect "$tmp/list.txt" "module: $tmp/ext_grey-build/plugins/gi_effect_ext_grey\.so$" \
  "ext_grey module path not listed"
if grep -q "^refused:" "$tmp/list.txt"; then fail "a module was refused"; fi

render() {  # NAME EFFECTS [more gi-render arguments]
  local name="$1" effects="$2"
  shift 2
  "$gi" --scene default --effects "$effects" --print-graph --validation --width 160 \
    --height 120 --out "$tmp/$name.png" "$@" >"$tmp/$name.log" 2>&1 || {
    cat "$tmp/$name.log" >&2
    fail "gi-render --effects '$effects' ($name)"
  }
  [ -s "$tmp/$name.png" ] || fail "$name.png not written"
}
step "render with and without the vignette"
render v vignette
cat "$tmp/v.log"
expect "$tmp/v.log" "^  \[run\] +vignette$" "vignette pass not executed"
expect "$tmp/v.log" "^      reads: lit$" "vignette pass does not read lit"
render base ""
if grep -q "vignette" "$tmp/base.log"; then fail "vignette ran without being asked for"; fi
python3 "$src/tests/external_effect/corners.py" "$tmp/v.png" "$tmp/base.png" ||
  fail "the vignette does not darken the corners"
# Uniform-only setting: strength 0 leaves the image as it was.
render v0 vignette --set vignette.strength=0
python3 "$src/tests/external_effect/corners.py" "$tmp/v0.png" "$tmp/base.png" >/dev/null &&
  fail "vignette.strength=0 still darkens the corners"

step "render the copied template after the vignette, and its debug view"
render both vignette,ext_grey
expect "$tmp/both.log" "^  \[run\] +vignette$" "vignette pass not executed"
expect "$tmp/both.log" "^  \[run\] +ext_grey$" "ext_grey pass not executed"
render grey_view ext_grey --view ext_grey
# Its debug view as linear floats: strength 1 is grey (R = G = B), strength 0 keeps the room's
# coloured walls.
for strength in 0 1; do
  "$gi" --scene default --effects ext_grey --view ext_grey --set "ext_grey.strength=$strength" \
    --validation --width 160 --height 120 --out "$tmp/grey$strength.pfm" >"$tmp/grey$strength.log" \
    2>&1 || { cat "$tmp/grey$strength.log" >&2; fail "gi-render ext_grey.strength=$strength"; }
done
python3 - "$tmp/grey0.pfm" "$tmp/grey1.pfm" <<'PY' || fail "the copied template does not desaturate"
import struct, sys
def chroma(path):  # the largest |R - G| or |G - B| relative to the pixel's brightest channel
    data = open(path, "rb").read()
    header = data.split(b"\n", 3)
    w, h = map(int, header[1].split())
    px = struct.unpack("<%df" % (3 * w * h), header[3][: 12 * w * h])
    worst = 0.0
    for i in range(0, len(px), 3):
        r, g, b = px[i : i + 3]
        worst = max(worst, max(abs(r - g), abs(g - b)) / max(r, g, b, 1e-6))
    return worst
kept, grey = chroma(sys.argv[1]), chroma(sys.argv[2])
print(f"chroma: strength 0 {kept:.4f}, strength 1 {grey:.6f}")
sys.exit(0 if grey < 1e-3 and kept > 0.1 else 1)
PY

step "second_view: the scene drawn again through GpuScene equals the main G-buffer's depth"
render_pfm() {  # NAME VIEW: the second_view effect, that view as linear floats
  "$gi" --scene default --effects second_view --print-graph --validation --width 160 \
    --height 120 --view "$2" --out "$tmp/$1.pfm" >"$tmp/$1.log" 2>&1 || {
    cat "$tmp/$1.log" >&2
    fail "gi-render --view $2"
  }
}
render_pfm main_depth depth
render_pfm sv_depth second_view_depth
render_pfm sv_gdepth second_view_gdepth
render_pfm sv_flux second_view_flux
render_pfm sv_irradiance second_view_irradiance
expect "$tmp/sv_depth.log" "^  \[run\] +second_view$" "second_view pass not executed"
python3 "$src/tests/external_effect/compare_pfm.py" "$tmp/main_depth.pfm" "$tmp/sv_depth.pfm" 1e-6 ||
  fail "depth-only second view differs from the main G-buffer's depth"
python3 "$src/tests/external_effect/compare_pfm.py" "$tmp/main_depth.pfm" "$tmp/sv_gdepth.pfm" 1e-6 ||
  fail "G-buffer second view differs from the main G-buffer's depth"
python3 - "$tmp/sv_flux.pfm" <<'PY' || fail "reflective shadow map flux not positive and finite"
import math, struct, sys
data = open(sys.argv[1], "rb").read().split(b"\n", 3)
w, h = map(int, data[1].split())
v = struct.unpack("<" + "f" * (w * h * 3), data[3][:w * h * 12])
assert all(math.isfinite(x) and x >= 0 for x in v), "non-finite or negative flux"
assert sum(v) > 0, "no flux"
print(f"rsm flux sum {sum(v):.4g} W over {w}x{h}")
PY

python3 - "$tmp/sv_irradiance.pfm" <<'PY' || fail "irradiance from lights.glsl/environment.glsl wrong"
import math, struct, sys
data = open(sys.argv[1], "rb").read().split(b"\n", 3)
w, h = map(int, data[1].split())
v = struct.unpack("<" + "f" * (w * h * 3), data[3][:w * h * 12])
assert all(math.isfinite(x) and x >= 0 for x in v), "non-finite or negative irradiance"
lum = sorted(v[i] + v[i + 1] + v[i + 2] for i in range(0, len(v), 3))
lum = [x for x in lum if x > 0]  # geometry (sky pixels are 0)
assert len(lum) > len(v) // 6, "no irradiance on the geometry"
# The default room: directly lit pixels and the point light's shadows (only the environment).
low, high = lum[len(lum) // 20], lum[len(lum) * 19 // 20]
print(f"irradiance 5%: {low:.3g}, 95%: {high:.3g}")
assert high > 4 * low, "no contrast between lit and shadowed pixels"
PY

step "SSAO (in-tree plugin) together with the out-of-tree vignette: exact executed passes"
if [ -f "$(dirname "$gi")/plugins/gi_effect_ssao.so" ]; then
  render ssao_vignette ssao,vignette
  got=$(sed -n 's/^  \[run\] *//p' "$tmp/ssao_vignette.log" | tr '\n' ' ')
  want="gbuffer shadow_0 ssao ssao_blur lighting vignette tonemap "
  [ "$got" = "$want" ] || fail "executed passes: got '$got', want '$want'"
fi
step "the installed apps from the prefix alone (run from an empty folder)"
share="$prefix/share/gi"
mkdir -p "$tmp/run" && cd "$tmp/run"
"$gi" --scene "$share/scenes/cornell_box.json" --effects vignette --preset medium --validation \
  --width 96 --height 72 --out "$tmp/run/box.png" >"$tmp/box.log" 2>&1 || {
  cat "$tmp/box.log" >&2
  fail "installed gi-render on the installed Cornell box scene"
}
"$prefix/bin/gi-reference" --scene "$share/scenes/cornell_box.json" --quantity ao --radius 0.5 \
  --spp 4 --width 96 --height 72 --out "$tmp/run/ao.pfm" >"$tmp/ref.log" 2>&1 || {
  cat "$tmp/ref.log" >&2
  fail "installed gi-reference"
}
[ -s "$tmp/run/ao.pfm" ] || fail "gi-reference wrote no image"
"$prefix/bin/gi-bench" --scenes default,"$share/scenes/bunny_on_plane.json" \
  --effects vignette,ext_grey,none --presets none --width 64 --height 48 --frames 1 --reps 2 \
  --ref-spp 4 --cache "$tmp/cache" --no-progress --out "$tmp/run/bench" >"$tmp/bench.log" 2>&1 || {
  cat "$tmp/bench.log" >&2
  fail "installed gi-bench"
}
expect "$tmp/run/bench/results.csv" "vignette" "gi-bench did not score the vignette"
expect "$tmp/run/bench/results.csv" "ext_grey" "gi-bench did not score ext_grey"
[ -s "$tmp/run/bench/report.md" ] || fail "gi-bench wrote no report"
if command -v xvfb-run >/dev/null; then
  sed -e 's/gtao/vignette/g' -e 's/^view ao .*/view vignette/' "$share/scripts/tour.txt" >"$tmp/tour.txt"
  xvfb-run -a -s '-screen 0 640x480x24' "$prefix/bin/gi-demo" --scene "$share/scenes/demo.json" \
    --effects vignette --validation --width 160 --height 120 --script "$tmp/tour.txt" \
    >"$tmp/demo.log" 2>&1 || {
    cat "$tmp/demo.log" >&2
    fail "installed gi-demo with the shipped script"
  }
  expect "$tmp/demo.log" "^passes:.* vignette" "gi-demo did not run the vignette"
  [ -s "$tmp/run/out/tour-low.png" ] || fail "gi-demo wrote no screenshot"
  if grep -qi "validation" "$tmp/demo.log"; then
    cat "$tmp/demo.log" >&2
    fail "validation messages from the installed gi-demo"
  fi
fi
step "passed"
