#version 460
// Environment VPLs (seed 002 §5, "Environment Maps": the map as importance-sampled VPLs whose
// ISMs give the shadows). VPL i is directional: direction d_i (to the sky) from the point
// u_i = ((i + 0.5) / N, radical inverse of j + (phase + 0.5) / k^2 mod 1), i = phase + j k^2,
// through the engine's sampler (environment.glsl, the CPU sampler's tables), radiance L_i, pdf
// p_i per unit solid angle. The gathering's pixels of one interleaving phase take VPLs
// phase + j k^2: each phase gets a whole stratified set (the first coordinate every k^2-th
// stratum, the second a shifted van der Corput sequence), and so does their union. (With plain
// Hammersley points, i's low bits -- the phase -- fix the radical inverse's high bits: each
// phase saw one azimuth slice of the sky, and the blur left k-pixel stripes.) It carries the
// irradiance E_i = L_i / (N p_i) at normal incidence, so sum_i E_i max(n.d_i, 0) V_i is the
// Monte Carlo estimate of the irradiance int L V cos. Fixed points: a static environment gives
// the same VPLs every frame. Guard: p_i > 0 and a finite, non-zero E_i, else the VPL carries
// nothing (w = 0: not splatted). Record: position = (d_i, w), flux = (E_i, 0); also zeroes the
// padding to whole k x k blocks.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "ism_common.glsl"
#define GI_ENVIRONMENT_SET 0
#define GI_ENVIRONMENT_BINDING_MAP 2
#define GI_ENVIRONMENT_BINDING_SAMPLING 3
#include "environment.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 4, std430) writeonly buffer EnvVpls { Vpl vpls[]; };

float radicalInverse(uint i) { return float(bitfieldReverse(i)) * 2.3283064365386963e-10; }

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint n = uint(ism.envVpls.x), padded = uint(ism.envVpls.y);
  if (i >= padded) return;
  Vpl v;
  v.position = vec4(0.0, 1.0, 0.0, 0.0);
  v.normal = vec4(0.0);
  v.flux = vec4(0.0);
  if (i < n) {
    uint phases = uint(ism.gather.z), phase = i % phases, j = i / phases;
    float second = fract(radicalInverse(j) + (float(phase) + 0.5) / float(phases));
    EnvironmentSample s = sampleEnvironment(vec2((float(i) + 0.5) / float(n), second));
    vec3 e = s.radiance / (float(n) * max(s.pdf, 1e-30));
    float m = max(e.r, max(e.g, e.b));
    if (s.pdf > 0.0 && !isnan(e.r + e.g + e.b) && !isinf(e.r + e.g + e.b) && m > 0.0) {
      v.position = vec4(s.direction, 1.0);
      v.flux = vec4(max(e, vec3(0.0)), 0.0);
    }
  }
  vpls[i] = v;
}
