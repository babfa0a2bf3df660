// Cross-bilateral filter of the Alchemy obscurance along one axis (seed 003 §2.5: separable,
// depth-aware), included by alchemy_blur_x.comp (writes the packed RGBA32F texel again, for the
// y pass) and alchemy_blur_y.comp (writes the final R16F "ao"). One fetch per tap: the input
// texel carries (AO, 1/z, d(1/z)/dx, d(1/z)/dy) (alchemy.comp), so neither depth nor normals are
// read again. No shared memory: on llvmpipe shared-memory accesses are gathered lane by lane
// and workgroup barriers are costly (the SSAO blur measured a tiled version twice as slow).
//
// Spatial weights: a box of width 2 radius with half-weight ends ([.5 1 1 1 .5] for radius 2):
// for even radii every phase of the 4x4 interleave gets the same weight along each axis, so the
// pattern cancels exactly on flat regions.
// Edge stopping: a neighbour gets zero weight when its view distance differs by more than the
// tolerance (kBlurDepthTolerance x r) from the centre's tangent plane extended to it (1/z of a
// plane is affine in screen space, so the prediction is exact along a plane at any angle; the
// plane comes from the centre's normal). Across a depth edge or once a crease leaves the plane,
// the neighbour is rejected; sky neighbours (1/z = 0) always are.
#include "common.glsl"
#include "depth_aware_blur.glsl"  // depthAwareBlurWeight

layout(local_size_x = 32, local_size_y = 16) in;

layout(constant_id = 0) const int kRadius = 4;  // 1..gi::alchemy::kMaxBlurRadius

// Keep in sync with gi::alchemy::Uniforms (alchemy_kernel.h).
layout(set = 0, binding = 0) uniform AlchemyParams {
  float radius;         // r, world units
  float bias;           // beta
  float scale;          // 2 sigma / s
  float contrast;       // k
  float epsilon;        // denominator guard
  float blurTolerance;  // absolute, world units
  float radius2;        // r^2
  float pad;
  uvec4 taps[16];
} params;
layout(set = 0, binding = 1) uniform sampler2D inAO;
#ifdef ALCHEMY_BLUR_FINAL
layout(set = 0, binding = 2, r16f) uniform writeonly image2D outAO;
#else
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D outAO;
#endif

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = imageSize(outAO);
  if (p.x >= size.x || p.y >= size.y) return;

  vec4 c = texelFetch(inAO, p, 0);
  float ic = c.y;  // 1 / view distance (0: sky)
  float slope = dot(c.zw, vec2(kAxis));
  float tol = params.blurTolerance;
  float sum = c.x, weights = 1.0;
  for (int o = -kRadius; o <= kRadius; ++o) {
    if (o == 0) continue;
    bool inside;
    vec4 n = texelFetch(inAO, depthAwareBlurTap(p, o, kAxis, size, inside), 0);
    float w = inside ? depthAwareBlurWeight(o, kRadius, ic, slope, n.y, tol) : 0.0;
    sum += w * n.x;
    weights += w;
  }
  float ao = sum / weights;  // weights >= 1: the centre always counts
#ifdef ALCHEMY_BLUR_FINAL
  imageStore(outAO, p, vec4(ao));
#else
  imageStore(outAO, p, vec4(ao, c.yzw));
#endif
}
