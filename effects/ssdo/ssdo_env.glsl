// Shared by ssdo.glsl and ssdo_env_samples.comp (include after environment.glsl): how
// `environment_sampling` reads an equirect map.
#ifndef SSDO_ENV_GLSL
#define SSDO_ENV_GLSL

const vec2 kR2 = vec2(0.7548776662466927, 0.5698402909980532);  // Roberts' R2 sequence
const int kEnvironmentSlots = 16 * 32;  // gi::ssdo::kPhases x kMaxSamples: one per sample slot

// The map's radiance in direction d, read from the texel that contains it: the map as the
// engine's importance sampling sees it (piecewise constant). A bilinear read would spread a
// small bright source into neighbouring texels (a 2 x 2-texel sun: 23% of its light) that the
// sampler almost never picks, light a fixed sample set then misses.
vec3 environmentTexelRadiance(vec3 d) {
  vec2 uv = giEnvironmentUV(d);
  int w = giEnvWidth(), h = giEnvHeight();
  ivec2 t = clamp(ivec2(uv * vec2(w, h)), ivec2(0), ivec2(w - 1, h - 1));
  return giEnvTexel(t.x, t.y) * max(giEnvironment.scale.x, 0.0);
}

#endif
