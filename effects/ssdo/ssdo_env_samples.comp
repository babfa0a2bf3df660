#version 460
#extension GL_GOOGLE_include_directive : require
// The environment's importance samples of `environment_sampling=mis` (ssdo.glsl), once per
// frame instead of per pixel: sample slot f (phase x 32 + i) takes the point
// fract(0.5 + R2 f) through the engine's importance sampling (environment.glsl, the CPU
// sampler's tables): its direction, pdf and the radiance of its texel. Every pixel of a phase
// uses the same slots, so the table holds all there are.
// Record f: samples[2 f] = (direction, pdf), samples[2 f + 1] = (radiance, 0).
#define GI_ENVIRONMENT_SET 0
#define GI_ENVIRONMENT_BINDING_MAP 0
#define GI_ENVIRONMENT_BINDING_SAMPLING 1
#include "environment.glsl"
#include "ssdo_env.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 2, std430) writeonly buffer Samples { vec4 samples[]; };

void main() {
  int f = int(gl_GlobalInvocationID.x);
  if (f >= kEnvironmentSlots) return;
  EnvironmentSample es = sampleEnvironment(fract(vec2(0.5) + kR2 * float(f)));
  samples[2 * f] = vec4(es.direction, es.pdf);
  samples[2 * f + 1] = vec4(environmentTexelRadiance(es.direction), 0.0);
}
