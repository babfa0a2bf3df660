#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// The SSDO blur along y (radius 0: none), then the reflection: x the diffuse albedo
// (albedo x (1 - metallic), as the lighting pass's environment term) into `ambient` (alpha 1:
// replaces the engine's environment term) and, with the bounce, `indirect` (added by lighting;
// without it `indirect` is not published and outIndirect is the ambient image, never written).
#define GI_BLUR_AXIS 1
#include "ssdo_blur.glsl"
layout(set = 0, binding = 3) uniform sampler2D gAlbedo;
layout(set = 0, binding = 4) uniform sampler2D gMaterial;
layout(set = 0, binding = 5, rgba16f) uniform writeonly image2D outAmbient;
layout(set = 0, binding = 6, rgba16f) uniform writeonly image2D outIndirect;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  uvec4 centre = texelFetch(inRaw, p, 0);
  vec3 direct, bounce;
  ssdoBlur(p, size, centre, direct, bounce);
  vec3 diffuse = texelFetch(gAlbedo, p, 0).rgb * (1.0 - texelFetch(gMaterial, p, 0).g);
  // Guard: half floats overflow above 65504.
  imageStore(outAmbient, p, vec4(min(diffuse * direct, vec3(65000.0)), 1.0));
  if (kBounceTerm) imageStore(outIndirect, p, vec4(min(diffuse * bounce, vec3(65000.0)), 1.0));
}
