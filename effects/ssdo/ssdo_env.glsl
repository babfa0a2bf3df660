// Shared by ssdo.glsl and ssdo_env_samples.comp: the sample slots of `environment_sampling=mis`
// and the points that draw their directions (radiance: environment.glsl's
// environmentTexelRadiance, the map as its pdf describes it).
#ifndef SSDO_ENV_GLSL
#define SSDO_ENV_GLSL

const vec2 kR2 = vec2(0.7548776662466927, 0.5698402909980532);  // Roberts' R2 sequence
const int kEnvironmentSlots = 16 * 32;  // gi::ssdo::kPhases x kMaxSamples: one per sample slot

#endif
