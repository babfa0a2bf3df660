#include "gi/engine_settings.h"

#include "gi/errors.h"

namespace gi {

std::vector<SettingDesc> engineSettingDescs() {
  const RenderSettings d;  // the defaults are RenderSettings' own
  auto hints = [](SettingDesc desc, double step, bool logScale) {
    desc.step = step;
    desc.logScale = logScale;
    return desc;
  };
  return {
      hints({"shadow_map_size", SettingType::Int, double(d.shadowMapSize), 16, 8192,
             "texels per side of each shadow map (point lights: per cube face); the device "
             "limits it further: a point light's faces share one 3x2 atlas, which must fit its "
             "largest image (3 x size <= maxImageDimension2D, e.g. 5461 at 16384)",
             true},
            0, true),
      {"shadow_cache", SettingType::Bool, d.cacheShadows ? 1.0 : 0.0, 0, 1,
       "a light that did not move keeps its static casters' depth: each frame redraws only the "
       "dynamic casters (skinned, morphed, or moved once) over what they cover (the same maps; "
       "off: every map drawn whole every frame)"},
      {"shadow_update_period", SettingType::Int, double(d.shadowUpdatePeriod), 1, 8,
       "a moving light's shadow map is drawn whole every N-th frame (lights staggered); in "
       "between it keeps the views it was drawn with (shadows lag the light by up to N-1 "
       "frames) and only dynamic casters are redrawn (needs shadow_cache; 1: every frame, "
       "exact)"},
      {"pcf_radius", SettingType::Int, double(d.pcfRadius), 0, 3,
       "shadow filter: (2r+1)^2 texels per lookup (0: one hard-edged tap)"},
      hints({"exposure", SettingType::Float, double(d.exposure), 1e-3, 1e3,
             "exposure applied before tonemapping"},
            0, true),
      hints({"environment_intensity", SettingType::Float, double(d.environmentIntensity), 0, 100,
             "scales the environment (sky or map) radiance"},
            0.05, false),
      {"surface_points", SettingType::Int, double(d.surfacePoints), 0, double(1 << 24),
       "at least this many area-uniform surface points (effects may ask for more)", true},
      // Points are placed once per graph build: a new seed needs a rebuild too.
      {"surface_point_seed", SettingType::Int, double(d.surfacePointSeed), 0, 2147483647.0,
       "seed of the surface point placement", true},
  };
}

SettingValues engineSettingsOf(const RenderSettings& s) {
  SettingValues v(kEngineSettingsOwner, engineSettingDescs());
  const std::string origin = "RenderSettings";
  v.set("shadow_map_size", s.shadowMapSize, origin);
  v.set("shadow_cache", s.cacheShadows, origin);
  v.set("shadow_update_period", s.shadowUpdatePeriod, origin);
  v.set("pcf_radius", s.pcfRadius, origin);
  v.set("exposure", double(s.exposure), origin);
  v.set("environment_intensity", double(s.environmentIntensity), origin);
  v.set("surface_points", s.surfacePoints, origin);
  v.set("surface_point_seed", s.surfacePointSeed, origin);
  return v;
}

void applyEngineSettings(const SettingValues& v, RenderSettings& s) {
  if (v.owner() != kEngineSettingsOwner)
    throw Error(ErrorKind::InvalidData, "",
                "applyEngineSettings: got the settings of '" + v.owner() + "', not the engine's");
  s.shadowMapSize = uint32_t(v.integer("shadow_map_size"));
  s.cacheShadows = v.flag("shadow_cache");
  s.shadowUpdatePeriod = uint32_t(v.integer("shadow_update_period"));
  s.pcfRadius = uint32_t(v.integer("pcf_radius"));
  s.exposure = float(v.number("exposure"));
  s.environmentIntensity = float(v.number("environment_intensity"));
  s.surfacePoints = uint32_t(v.integer("surface_points"));
  s.surfacePointSeed = uint64_t(v.integer("surface_point_seed"));
}

}  // namespace gi
