// Depth-aware 4x4 box filter of the per-pixel sums (seed 001 §4.2), one axis per dispatch:
// obscurance_filter.comp runs it along x (texels -> texels), obscurance_resolve.comp along y
// and divides (texels -> "ao"). Included by both with GI_AXIS and GI_RESOLVE defined.
//
// Weights [.5 1 1 1 .5]: every phase of the 4x4 interleave gets the same weight along each axis
// (a 4-wide box, centred), so the pattern cancels on flat regions. A neighbour is skipped when
// its view distance differs by more than the tolerance (a fraction of R) from the centre's
// tangent plane extended to it (exact along planes at any angle; rejects depth edges and
// creases), as in ssao_blur.comp. Sums are filtered before dividing: W = sum N / sum D is the
// weighted-importance-sampling ratio over all 16 rotations.
//
// Input and intermediate texel (RGBA32UI, written by obscurance.comp): x = half2(N / n, D / n),
// y = float bits of 1 / view distance (0: sky, no geometry), z = half2 slopes of 1 / distance
// along x and y per pixel, w (MODE 3) = half2 of the colour numerator's g, b (x then holds
// its r and D + eta). One fetch per tap, no G-buffer reads. MODE 3 resolves to the RGBA16F
// "ambient" (GI_AMBIENT), the other modes to the R16F "ao".
#include "depth_aware_blur.glsl"  // depthAwareBlurWeight
#include "guards.glsl"

layout(local_size_x = 32, local_size_y = 16) in;

// 0 obscurance, 1 W (albedo), 2 W (emission), 3 ambient radiance (RGB)
layout(constant_id = 0) const int MODE = 0;
layout(constant_id = 1) const int RADIUS = 2;  // 2: the 4x4 box; 0: no filtering (resolve only)

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform ObscuranceParams {
  float radius;           // R, world units
  float bias;             // absolute, world units
  float filterTolerance;  // absolute, world units
  float guard;            // the transfer's denominator guard
  vec4 rotation[16];
  uvec4 kernel[16];
} obs;
layout(set = 0, binding = 2) uniform usampler2D inSums;
#if GI_RESOLVE && GI_AMBIENT
layout(set = 0, binding = 3, rgba16f) uniform writeonly image2D outImage;
#elif GI_RESOLVE
layout(set = 0, binding = 3, r16f) uniform writeonly image2D outImage;
#else
layout(set = 0, binding = 3, rgba32ui) uniform writeonly uimage2D outImage;
#endif

void store(ivec2 p, vec4 sums, uvec4 centre) {
#if GI_RESOLVE && GI_AMBIENT
  // Ambient radiance per unit diffuse albedo (alpha 2: the lighting pass multiplies by it);
  // D + eta >= eta > 0 per pixel, so the window's mean is too. Sky / no geometry (1 / distance
  // 0): alpha 0, the lighting pass's own term. Guards: finite, below the half-float maximum.
  vec3 a = max(vec3(sums.x, sums.zw) / max(sums.y, 1e-30), vec3(0.0));
  giGuard(GI_GUARD_NONFINITE, any(isnan(a)));
  giGuard(GI_GUARD_RANGE, any(greaterThan(a, vec3(65000.0))));
  a = mix(min(a, vec3(65000.0)), vec3(0.0), isnan(a));
  imageStore(outImage, p, uintBitsToFloat(centre.y) > 0.0 ? vec4(a, 2.0) : vec4(0.0));
#elif GI_RESOLVE
  float w = sums.x;
  if (MODE != 0) {
    // Guarded transfer ratio (obscurance_kernel.h: the phantom open sample): finite, in [0, 1]
    // for albedo in [0, 1] since N <= D, and 1 when every ray is closed by white occluders.
    float eta = obs.guard;
    giGuard(GI_GUARD_DENOMINATOR, sums.y < eta);  // the phantom sample outweighs the rays
    w = (sums.x + eta) / (sums.y + eta);
    if (MODE == 2) w = clamp(w, 0.0, 1.0);
  }
  imageStore(outImage, p, vec4(w));
#else
  imageStore(outImage, p,
             uvec4(packHalf2x16(sums.xy), centre.yz, MODE == 3 ? packHalf2x16(sums.zw) : 0u));
#endif
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  const ivec2 axis = GI_AXIS;

  uvec4 c = texelFetch(inSums, p, 0);
  vec4 sum = vec4(unpackHalf2x16(c.x), MODE == 3 ? unpackHalf2x16(c.w) : vec2(0.0));
  float ic = uintBitsToFloat(c.y);  // 1 / view distance; 0: sky
  if (RADIUS == 0 || !(ic > 0.0)) {  // no filter (folded at specialization), or sky: as is
    store(p, sum, c);
    return;
  }
  float slope = dot(unpackHalf2x16(c.z), vec2(axis));
  float tol = obs.filterTolerance;
  float weights = 1.0;
  for (int o = -RADIUS; o <= RADIUS; ++o) {
    if (o == 0) continue;
    bool inside;
    uvec4 t = texelFetch(inSums, depthAwareBlurTap(p, o, axis, size, inside), 0);
    float iq = uintBitsToFloat(t.y);
    float w = inside ? depthAwareBlurWeight(o, RADIUS, ic, slope, iq, tol) : 0.0;
    sum += w * vec4(unpackHalf2x16(t.x), MODE == 3 ? unpackHalf2x16(t.w) : vec2(0.0));
    weights += w;
  }
  store(p, sum / weights, c);  // weights >= 1: the centre always counts
}
