// Shared declarations of the engine's shaders. Keep in sync with FrameUniforms in
// engine/src/render/gpu_types.h (std140).
#ifndef GI_COMMON_GLSL
#define GI_COMMON_GLSL

struct FrameUniforms {
  mat4 view;
  mat4 proj;
  mat4 viewProj;
  mat4 invView;
  mat4 invProj;
  mat4 prevViewProj;
  vec4 viewport;      // width, height, 1/width, 1/height
  vec4 cameraPos;     // world space
  vec4 skyZenith;     // rgb, intensity
  vec4 skyHorizon;    // rgb, environment kind (0 sky, 1 constant)
  vec4 skyGround;     // rgb, unused
  vec4 params;        // exposure, light count, near, far
};

// Guard: normalising a zero or non-finite vector returns the fallback instead of NaN.
vec3 safeNormalize(vec3 v, vec3 fallback) {
  float len2 = dot(v, v);
  return (len2 > 1e-30 && !isinf(len2) && !isnan(len2)) ? v * inversesqrt(len2) : fallback;
}

// View-space position from a reverse-Z depth sample and the pixel's UV (0..1, y down).
vec3 viewPositionFromDepth(mat4 invProj, vec2 uv, float depth) {
  vec4 clip = vec4(uv * 2.0 - 1.0, depth, 1.0);
  vec4 view = invProj * clip;
  return view.xyz / view.w;
}

// Sky pixels keep depth 0 (the reverse-Z far plane clear value).
bool isSky(float depth) { return depth <= 0.0; }

// Procedural sky radiance in world direction `dir` (or the constant environment).
vec3 environmentRadiance(FrameUniforms f, vec3 dir) {
  if (f.skyHorizon.w > 0.5) return f.skyGround.rgb * f.skyZenith.w;
  float y = clamp(dir.y, -1.0, 1.0);
  vec3 c = y >= 0.0 ? mix(f.skyHorizon.rgb, f.skyZenith.rgb, sqrt(y))
                    : mix(f.skyHorizon.rgb, f.skyGround.rgb, sqrt(-y));
  return c * f.skyZenith.w;
}

// Cosine-weighted average of the environment around world normal n (irradiance / pi),
// a closed-form approximation good for smooth gradient skies.
vec3 environmentIrradianceOverPi(FrameUniforms f, vec3 n) {
  if (f.skyHorizon.w > 0.5) return f.skyGround.rgb * f.skyZenith.w;
  vec3 up = 0.5 * (f.skyZenith.rgb + f.skyHorizon.rgb);
  vec3 down = 0.5 * (f.skyGround.rgb + f.skyHorizon.rgb);
  return mix(down, up, 0.5 + 0.5 * clamp(n.y, -1.0, 1.0)) * f.skyZenith.w;
}

#endif
