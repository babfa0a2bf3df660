// The engine's own settings (shadow maps, exposure, environment, surface points), declared as
// typed settings like an effect's, under the owner name "engine": they come from
// RenderSettings' defaults < quality preset < scene < --set engine.KEY=V (gi/effect_config.h),
// with the same validation and messages.
#pragma once

#include <vector>

#include "gi/render_settings.h"
#include "gi/settings.h"

namespace gi {

inline constexpr const char* kEngineSettingsOwner = "engine";

// shadow_map_size, pcf_radius, exposure, environment_intensity, surface_points,
// surface_point_seed; defaults are RenderSettings{}'s. Those that change the graph:
// shadow_map_size, surface_points, surface_point_seed (points are placed once per graph).
std::vector<SettingDesc> engineSettingDescs();
// The values `s` holds now. Throws gi::Error(InvalidData) naming the key when a field is out
// of the declared range.
SettingValues engineSettingsOf(const RenderSettings& s);
// Writes the values into `s` (other fields untouched). `v` must hold the engine's settings.
void applyEngineSettings(const SettingValues& v, RenderSettings& s);

}  // namespace gi
