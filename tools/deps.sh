#!/usr/bin/env bash
# Shared set-up for tools/demo and tools/test: install the Debian packages the project needs
# (only the missing ones), then configure and build with the given CMake preset.
set -euo pipefail

GI_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

GI_PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libvulkan-dev vulkan-validationlayers mesa-vulkan-drivers vulkan-tools
  glslang-tools glslang-dev spirv-tools libspirv-cross-c-shared-dev
  libglm-dev libtinygltf-dev nlohmann-json3-dev libopenmesh-dev libglfw3-dev libimgui-dev
  libstb-dev libembree-dev libgtest-dev libbenchmark-dev clang-format clang-tidy
  assimp-testmodels python3  # python3: the external-effect test checks images with it
  xvfb xauth  # test_window runs gi-render --window on a virtual X server
  xdotool     # test_demo taps keys and clicks in gi-demo's window under it
  clang-14 libclang-rt-14-dev  # tools/fuzz: libFuzzer (the fuzz_smoke test)
)

gi_install_missing() {
  local missing=()
  for p in "${GI_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  local line="apt-get install -y --no-install-recommends ${missing[*]}"
  echo "gi: missing Debian packages: ${missing[*]}"
  echo "gi: running: $line"
  if [ "$(id -u)" -ne 0 ]; then
    echo "gi: error: not root, cannot install. Run as root: apt-get update && $line" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  if ! { apt-get update -qq && apt-get install -y -q --no-install-recommends "${missing[@]}"; }; then
    echo "gi: error: package installation failed. Run by hand: apt-get update && $line" >&2
    exit 1
  fi
}

gi_build() {
  local preset="$1"
  cd "$GI_ROOT"
  # Re-running configure on an existing tree is cheap and picks up new files.
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset"
}
