// What a frame is asked to render (size, engine settings, view, effects): plain data of the
// configuration layer, no Vulkan. gi/effect_config.h resolves it from presets, scenes and the
// command line; gi::Renderer renders it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gi/settings.h"

namespace gi {

// One requested effect with its resolved settings.
struct EffectConfig {
  std::string name;
  SettingValues settings;
};

struct RenderSettings {
  uint32_t width = 640, height = 480;
  float exposure = 1.0f;
  bool floorPass = false;  // also keep the floor pass (for timing baselines)
  // Shadow maps: texels per side of a directional/spot map and of each point-light cube face
  // (a point light renders its 6 faces into one 3x2 atlas). Every light with castsShadows that
  // sees the scene gets one "shadow_<light index>" pass drawing its layer of "shadow_maps".
  uint32_t shadowMapSize = 1024;
  uint32_t pcfRadius = 1;             // PCF kernel (2r+1)^2 texels
  float environmentIntensity = 1.0f;  // scales the environment (sky/map) radiance
  // Point representation (gi/surface_points.h): at least this many points (effects may ask
  // for more), placed with this seed. 0 and no effect asking: no points, no pass.
  uint32_t surfacePoints = 0;
  // Profiling: submit each pass on its own and wait for it, so each pass's timestamps cover
  // exactly its own work. A CPU driver (lavapipe) otherwise lets a pass's work spill into the
  // timing of the next pass that waits for it. Costs one submission per pass.
  bool isolatePasses = false;
  uint64_t surfacePointSeed = 1;
  // Debug: false gives every transient texture its own memory, so that readAllTextures() sees
  // each one's last version (robustness sweeps); true lets non-overlapping lifetimes share it.
  bool aliasTransients = true;
  // Skip drawing instances whose posed bounds lie outside a view's frustum (main camera, shadow
  // maps, cube faces, depth layers): the same image, fewer draws. Off for A/B measurements.
  bool cullDraws = true;
  // Shadow maps cost only what changed: a light that did not move keeps its static casters'
  // depth in a cache; each frame redraws only the dynamic casters (skinned, morphed, or moved
  // once) over the texels they cover. The same maps bit for bit; off for A/B measurements.
  bool cacheShadows = true;
  // Amortised shadows of moving lights (with cacheShadows): a moving light's map is drawn whole
  // every N-th frame (the lights staggered); in between it keeps the views it was drawn with
  // (its shadows lag the light by up to N-1 frames) and only the dynamic casters are redrawn
  // into it. 1: every frame, exact.
  uint32_t shadowUpdatePeriod = 1;
  std::string view =
      "output";  // the resource the frame delivers (a G-buffer channel, an effect's view)
  // Resources readTarget() will read besides `view`: kept intact to the end of the frame (the
  // frame graph otherwise lets later passes reuse their memory). A name this frame does not
  // produce is skipped (e.g. "ao" without an AO effect); readTarget() of it fails as always.
  std::vector<std::string> keepForReadback;
  std::vector<EffectConfig> effects;
};

}  // namespace gi
