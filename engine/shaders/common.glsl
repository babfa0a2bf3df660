// Shared declarations of the engine's and the effects' shaders. Keep in sync with the C++
// mirrors in engine/include/gi/frame_uniforms.h and gi/gpu_scene.h.
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
  vec4 skyHorizon;    // rgb, environment kind (0 sky, 1 constant, 2 equirect map)
  vec4 skyGround;     // rgb, unused
  vec4 params;        // exposure, light count, near, far
  vec4 irradianceSH[9];  // rgb: SH9 of the environment's irradiance (cosine lobe convolved,
                         // intensity included), world space; see gi/environment.h
  vec4 time;          // seconds (animation clock), frame index, seconds since last frame, 0
  vec4 options;       // PCF radius in texels, 0, 0, 0
};

// One drawn mesh instance. Keep in sync with gi::GpuInstance in gi/gpu_scene.h.
struct Instance {
  mat4 model;
  mat4 prevModel;
  mat4 normalMatrix;  // cofactor of the model's 3x3: finite even for singular transforms
  uvec4 material;     // x: material index, y: first vertex of its (deformed) vertices
};

// Guard: normalising a zero or non-finite vector returns the fallback instead of NaN.
vec3 safeNormalize(vec3 v, vec3 fallback) {
  float len2 = dot(v, v);
  return (len2 > 1e-30 && !isinf(len2) && !isnan(len2)) ? v * inversesqrt(len2) : fallback;
}

// Guard: the lit image is RGBA16F, whose largest value is 65504 (above it a half float is inf).
// Radiance is clamped to +-GI_MAX_RADIANCE where it is stored, so a legal extreme (an
// environment, light or emission of 1e38) gives the brightest finite value, never inf; a NaN
// reads 0. (Values in range pass unchanged.)
const float GI_MAX_RADIANCE = 65504.0;
vec3 giClampRadiance(vec3 c) {
  return mix(clamp(c, vec3(-GI_MAX_RADIANCE), vec3(GI_MAX_RADIANCE)), vec3(0.0), isnan(c));
}

// View-space position from a reverse-Z depth sample and the pixel's UV (0..1, y down).
vec3 viewPositionFromDepth(mat4 invProj, vec2 uv, float depth) {
  vec4 clip = vec4(uv * 2.0 - 1.0, depth, 1.0);
  vec4 view = invProj * clip;
  return view.xyz / view.w;
}

// Sky pixels keep depth 0 (the reverse-Z far plane clear value).
bool isSky(float depth) { return depth <= 0.0; }

// Irradiance arriving at a surface with world normal n / pi (SH9, exact for constant
// environments, the usual ~1-3% approximation for skies and maps).
vec3 environmentIrradianceOverPi(FrameUniforms f, vec3 n) {
  float x = n.x, y = n.y, z = n.z;
  vec3 e = f.irradianceSH[0].rgb * 0.282095 + f.irradianceSH[1].rgb * (0.488603 * y) +
           f.irradianceSH[2].rgb * (0.488603 * z) + f.irradianceSH[3].rgb * (0.488603 * x) +
           f.irradianceSH[4].rgb * (1.092548 * x * y) + f.irradianceSH[5].rgb * (1.092548 * y * z) +
           f.irradianceSH[6].rgb * (0.315392 * (3.0 * z * z - 1.0)) +
           f.irradianceSH[7].rgb * (1.092548 * x * z) +
           f.irradianceSH[8].rgb * (0.546274 * (x * x - y * y));
  return max(e, vec3(0.0)) * (1.0 / 3.14159265358979);
}

// Equirect mapping of gi/environment.h: u = atan(z, x) / 2pi in [0, 1), v = acos(y) / pi.
vec2 equirectUV(vec3 d) {
  d = safeNormalize(d, vec3(0, 1, 0));
  float u = atan(d.z, d.x) * (1.0 / (2.0 * 3.14159265358979));
  return vec2(u < 0.0 ? u + 1.0 : u, acos(clamp(d.y, -1.0, 1.0)) * (1.0 / 3.14159265358979));
}

// The procedural sky (environment kind 0) in world direction `dir`.
vec3 proceduralSkyRadiance(FrameUniforms f, vec3 dir) {
  float y = clamp(dir.y, -1.0, 1.0);
  vec3 c = y >= 0.0 ? mix(f.skyHorizon.rgb, f.skyZenith.rgb, sqrt(y))
                    : mix(f.skyHorizon.rgb, f.skyGround.rgb, sqrt(-y));
  return c * f.skyZenith.w;
}

// Environment radiance in world direction `dir`. Shaders without the map texture get its
// low-frequency (SH) approximation for kind 2; lighting.comp samples the map itself.
vec3 environmentRadiance(FrameUniforms f, vec3 dir) {
  if (f.skyHorizon.w > 1.5) return environmentIrradianceOverPi(f, dir);
  if (f.skyHorizon.w > 0.5) return f.skyGround.rgb * f.skyZenith.w;
  return proceduralSkyRadiance(f, dir);
}

#endif
