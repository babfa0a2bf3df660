#version 460
// Irradiance at each pixel of the main view from the engine's published lights (lights.glsl:
// the same incident light and shadow-map test the lighting pass uses) plus a one-sample
// importance-sampled estimate of the environment (environment.glsl): what an effect outside
// the engine's tree can compute from the installed shader includes.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D gDepth;
#define GI_GBUFFER_BINDING 2
#include "gbuffer.glsl"
#define GI_LIGHTS_SET 0
#define GI_LIGHTS_BINDING 3
#define GI_SHADOW_VIEWS_BINDING 4
#define GI_SHADOW_MAPS_BINDING 5
#include "lights.glsl"
#define GI_ENVIRONMENT_SET 0
#define GI_ENVIRONMENT_BINDING_MAP 6
#define GI_ENVIRONMENT_BINDING_SAMPLING 7
#include "environment.glsl"
layout(set = 0, binding = 8, rgba16f) uniform writeonly image2D outIrradiance;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;
  float depth = texelFetch(gDepth, p, 0).r;
  if (isSky(depth)) {
    imageStore(outIrradiance, p, vec4(0.0));
    return;
  }
  vec2 uv = (vec2(p) + 0.5) * frame.viewport.zw;
  vec3 pos = viewPositionFromDepth(frame.invProj, uv, depth);
  vec3 n = giGBufferNormal(p);
  vec3 e = vec3(0.0);
  for (int i = 0; i < lightCount(); ++i) {
    vec3 l;
    vec3 incident = lightIncident(lights[i], pos, l);
    float ndl = max(dot(n, l), 0.0);
    if (ndl > 0.0) e += incident * ndl * shadowFactor(lights[i], pos, n, ndl);
  }
  // One environment sample per pixel (an R2 sequence over the pixels), unoccluded.
  EnvironmentSample s = sampleEnvironment(fract(vec2(p) * vec2(0.7548776662, 0.5698402910)));
  float c = max(dot(mat3(frame.invView) * n, s.direction), 0.0);
  if (s.pdf > 0.0) e += s.radiance * c / s.pdf;
  imageStore(outIrradiance, p, vec4(e, 1.0));
}
