// The SSDO blur along y (radius 0: none) into the outputs, included by ssdo_resolve.comp (with
// the bounce) and ssdo_resolve_ambient.comp (without). `ambient` is the directional term per
// unit diffuse albedo (alpha 2: the lighting pass multiplies by albedo x (1 - metallic), which
// it reads anyway), so without the bounce this pass reads no G-buffer colour; with it,
// `indirect` is the bounce term x the diffuse albedo (a radiance, as the lighting pass adds it).
#define GI_BLUR_AXIS 1
#include "ssdo_blur.glsl"
layout(set = 0, binding = 5, rgba16f) uniform writeonly image2D outAmbient;
#ifdef SSDO_RESOLVE_INDIRECT
#define GI_GBUFFER_BINDING 3
#include "gbuffer.glsl"  // the packed G-buffer (albedo, metallic)
layout(set = 0, binding = 6, rgba16f) uniform writeonly image2D outIndirect;
#endif

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  uvec4 centre = texelFetch(inRaw, p, 0);
  vec3 direct, bounce;
  ssdoBlur(p, size, centre, direct, bounce);
  // Guard: half floats overflow above 65504.
  imageStore(outAmbient, p, vec4(min(direct, vec3(65000.0)), 2.0));
#ifdef SSDO_RESOLVE_INDIRECT
  uvec4 g = giGBufferLoad(p);
  vec3 diffuse = giGBufferAlbedo(g) * (1.0 - giGBufferMetallic(g));
  imageStore(outIndirect, p, vec4(min(diffuse * bounce, vec3(65000.0)), 1.0));
#endif
}
