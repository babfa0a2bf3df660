// The scene's environment in shaders (gi::EnvironmentGpu, engine/src/render/environment_gpu.h):
// importance sampling proportional to luminance x solid angle, the pdf of any direction and
// the map's radiance. Sampling is the CPU gi::EnvironmentSampler's: the same tables searched
// the same way, so a given u gives the same texel, direction and pdf on both.
//
// Include after defining
//   #define GI_ENVIRONMENT_SET 0
//   #define GI_ENVIRONMENT_BINDING_MAP 5       // sampler2D: EnvironmentGpu::map() (any filter:
//                                              // it is read with texelFetch)
//   #define GI_ENVIRONMENT_BINDING_SAMPLING 6  // storage buffer: EnvironmentGpu::samplingBuffer()
//
// Sampling buffer (std430; W x H = the map's size; offsets count floats into data[]):
//   uvec4 header   W, H, kind (EnvironmentGpu::kind(), as FrameUniforms.skyHorizon.w), 0
//   vec4  scale    intensity (>= 0), 0, 0, 0
//   data[0 .. H]                  marginal CDF over rows: [0] = 0, [H] = 1
//   data[M .. M + H(W+1))         M = H+1: row y's CDF over columns at M + y(W+1), [W] = 1
//   data[P .. P + WH)             P = M + H(W+1): pdf per unit solid angle of texel (x, y) at
//                                 P + yW + x (finite; a black map holds 1 / 4pi everywhere)
//   data[C .. C + H]              C = P + WH: cos(theta) of row y's top edge (C + H: bottom)
// World space, +y up; u = atan(z, x) / 2pi in [0, 1), v = acos(y) / pi; row 0 looks up.
#ifndef GI_ENVIRONMENT_GLSL
#define GI_ENVIRONMENT_GLSL

#if !defined(GI_ENVIRONMENT_SET) || !defined(GI_ENVIRONMENT_BINDING_MAP) || \
    !defined(GI_ENVIRONMENT_BINDING_SAMPLING)
#error "environment.glsl: define GI_ENVIRONMENT_SET, _BINDING_MAP and _BINDING_SAMPLING first"
#endif

layout(set = GI_ENVIRONMENT_SET, binding = GI_ENVIRONMENT_BINDING_MAP) uniform sampler2D
    giEnvironmentMap;
layout(set = GI_ENVIRONMENT_SET, binding = GI_ENVIRONMENT_BINDING_SAMPLING,
       std430) readonly buffer GiEnvironmentSampling {
  uvec4 header;
  vec4 scale;
  float data[];
}
giEnvironment;

struct EnvironmentSample {
  vec3 direction;  // world space, unit length
  float pdf;       // per unit solid angle, > 0
  vec3 radiance;   // environmentMapRadiance(direction)
};

const float GI_ENV_PI = 3.14159265358979;
const float GI_ENV_BELOW_ONE = 0.99999994;  // largest float < 1

int giEnvWidth() { return max(int(giEnvironment.header.x), 1); }
int giEnvHeight() { return max(int(giEnvironment.header.y), 1); }
int giEnvConditional() { return giEnvHeight() + 1; }
int giEnvTexelPdf() { return giEnvConditional() + giEnvHeight() * (giEnvWidth() + 1); }
int giEnvRowCos() { return giEnvTexelPdf() + giEnvWidth() * giEnvHeight(); }

// Index in [0, n) of the first cdf[first + i + 1] > u (std::upper_bound over cdf[1..n], as
// the CPU sampler): intervals of probability 0 are never chosen.
int giEnvSearchCdf(int first, int n, float u) {
  int lo = 1, count = n;
  while (count > 0) {
    int step = count / 2, mid = lo + step;
    if (!(u < giEnvironment.data[first + mid])) {
      lo = mid + 1;
      count -= step + 1;
    } else {
      count = step;
    }
  }
  return clamp(lo - 1, 0, n - 1);
}

// Equirect coordinates of a direction; zero, NaN and huge vectors read as +y, and the poles
// (atan(0, 0) is undefined in GLSL) as u = 0, like std::atan2 in gi::equirectUV.
vec2 giEnvironmentUV(vec3 d) {
  float m = max(abs(d.x), max(abs(d.y), abs(d.z)));
  d = (m > 0.0 && !isinf(m)) ? normalize(d / m) : vec3(0.0, 1.0, 0.0);
  float u = (d.x != 0.0 || d.z != 0.0) ? atan(d.z, d.x) * (0.5 / GI_ENV_PI) : 0.0;
  u = u < 0.0 ? u + 1.0 : u;
  return vec2(min(u, GI_ENV_BELOW_ONE), acos(clamp(d.y, -1.0, 1.0)) * (1.0 / GI_ENV_PI));
}

vec3 giEnvTexel(int x, int y) {
  int w = giEnvWidth();
  x = x < 0 ? x + w : (x >= w ? x - w : x);  // wraps in phi (GLSL % is undefined for x < 0)
  return texelFetch(giEnvironmentMap, ivec2(x, clamp(y, 0, giEnvHeight() - 1)), 0).rgb;
}

// Bilinear map radiance x intensity: wraps in phi, clamps at the poles (gi::environmentLookup).
vec3 environmentMapRadiance(vec3 direction) {
  vec2 uv = giEnvironmentUV(direction);
  float fx = uv.x * float(giEnvWidth()) - 0.5, fy = uv.y * float(giEnvHeight()) - 0.5;
  int x0 = int(floor(fx)), y0 = int(floor(fy));
  float ax = fx - float(x0), ay = fy - float(y0);
  vec3 top = mix(giEnvTexel(x0, y0), giEnvTexel(x0 + 1, y0), ax);
  vec3 bottom = mix(giEnvTexel(x0, y0 + 1), giEnvTexel(x0 + 1, y0 + 1), ax);
  return mix(top, bottom, ay) * max(giEnvironment.scale.x, 0.0);
}

// The texel that contains `direction`: the cell over which sampleEnvironment's pdf is constant.
ivec2 giEnvTexelOf(vec3 direction) {
  vec2 uv = giEnvironmentUV(direction);
  int w = giEnvWidth(), h = giEnvHeight();
  return ivec2(clamp(int(uv.x * float(w)), 0, w - 1), clamp(int(uv.y * float(h)), 0, h - 1));
}

// Pdf per unit solid angle with which sampleEnvironment picks `direction` (0 where it never
// does; never NaN).
float environmentPdf(vec3 direction) {
  ivec2 t = giEnvTexelOf(direction);
  return giEnvironment.data[giEnvTexelPdf() + t.y * giEnvWidth() + t.x];
}

// The radiance x intensity of the texel that contains `direction`: the piecewise-constant map
// the pdf describes. Estimators that weight by environmentPdf need it: the bilinear
// environmentMapRadiance spreads a small bright source into neighbouring texels the sampler
// almost never picks (a 2 x 2-texel sun: 23% of its light), which a fixed sample set misses.
vec3 environmentTexelRadiance(vec3 direction) {
  ivec2 t = giEnvTexelOf(direction);
  return giEnvTexel(t.x, t.y) * max(giEnvironment.scale.x, 0.0);
}

// u uniform in [0, 1)^2 (NaN reads as 0, values >= 1 as just below 1): a row from the marginal
// CDF (u.x), a column from that row's CDF (u.y), then uniform in phi and cos(theta) inside
// the texel, exactly as EnvironmentSampler::sample(u.x, u.y).
EnvironmentSample sampleEnvironment(vec2 u) {
  u = vec2(isnan(u.x) ? 0.0 : u.x, isnan(u.y) ? 0.0 : u.y);
  u = clamp(u, vec2(0.0), vec2(GI_ENV_BELOW_ONE));
  int w = giEnvWidth(), h = giEnvHeight();
  int y = giEnvSearchCdf(0, h, u.x);
  float rowLo = giEnvironment.data[y], rowHi = giEnvironment.data[y + 1];
  float fy = rowHi > rowLo ? clamp((u.x - rowLo) / (rowHi - rowLo), 0.0, 1.0) : 0.5;
  int row = giEnvConditional() + y * (w + 1);
  int x = giEnvSearchCdf(row, w, u.y);
  float lo = giEnvironment.data[row + x], hi = giEnvironment.data[row + x + 1];
  float fx = hi > lo ? clamp((u.y - lo) / (hi - lo), 0.0, 1.0) : 0.5;

  float c0 = giEnvironment.data[giEnvRowCos() + y];
  float c1 = giEnvironment.data[giEnvRowCos() + y + 1];
  float cosTheta = clamp(c0 + (c1 - c0) * fy, -1.0, 1.0);
  float sinTheta = sqrt(max(0.0, 1.0 - cosTheta * cosTheta));  // 0 at the poles, never NaN
  float phi = 2.0 * GI_ENV_PI * (float(x) + fx) / float(w);
  // cos/sin of phi - pi in [-pi, pi], where GPU sin/cos are most accurate.
  float a = phi - GI_ENV_PI;

  EnvironmentSample s;
  s.direction = vec3(-sinTheta * cos(a), cosTheta, -sinTheta * sin(a));
  s.pdf = giEnvironment.data[giEnvTexelPdf() + y * w + x];
  s.radiance = environmentMapRadiance(s.direction);
  return s;
}

#endif
