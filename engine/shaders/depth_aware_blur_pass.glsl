// One axis of the engine's depth-aware blur (gi/depth_aware_blur.h, weights and edge stopping
// in depth_aware_blur.glsl), included by depth_aware_blur_x.comp (keeps the packed texel for
// the y pass), depth_aware_blur_y.comp (writes the final value) and
// depth_aware_blur_y_packed.comp (keeps it for the upsample). One fetch per tap, no shared
// memory: on llvmpipe every shared-memory access is gathered lane by lane and barriers are
// costly. Include after defining GI_BLUR_AXIS (0: x, 1: y), GI_BLUR_KEEP_PACKED where the
// packed texel is kept, and declaring `outValue` (binding 1).
#include "common.glsl"
#include "depth_aware_blur.glsl"  // depthAwareBlurWeight

layout(local_size_x = 32, local_size_y = 16) in;

layout(set = 0, binding = 0) uniform sampler2D inPacked;  // depthAwareBlurPack texels
layout(push_constant) uniform Push { float tolerance; } push;  // world units
// Set at pipeline creation: the tap loop unrolls.
layout(constant_id = 0) const int kRadius = 2;  // 1..gi::DepthAwareBlur::kMaxRadius

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(inPacked, 0);
  if (p.x >= size.x || p.y >= size.y) return;
  const ivec2 axis = GI_BLUR_AXIS == 0 ? ivec2(1, 0) : ivec2(0, 1);

  vec4 centre = texelFetch(inPacked, p, 0);
  float ic = centre.y;
  float slope = GI_BLUR_AXIS == 0 ? centre.z : centre.w;
  float sum = centre.x, weights = 1.0;
  for (int o = -kRadius; o <= kRadius; ++o) {
    if (o == 0) continue;
    bool inside;
    vec4 t = texelFetch(inPacked, depthAwareBlurTap(p, o, axis, size, inside), 0);
    float w = inside ? depthAwareBlurWeight(o, kRadius, ic, slope, t.y, push.tolerance) : 0.0;
    sum += w * t.x;
    weights += w;
  }
  // weights >= 1: the centre always counts. Sky pixels (1/z = 0) keep their own value.
  float value = ic > 0.0 ? sum / weights : centre.x;
#ifdef GI_BLUR_KEEP_PACKED
  imageStore(outValue, p, vec4(value, centre.yzw));
#else
  imageStore(outValue, p, vec4(value));
#endif
}
