// Depth-aware (cross-bilateral) blur of the raw SSAO along one axis, included by
// ssao_blur_x.comp (writes the same packed texel for the y pass) and ssao_blur_y.comp (writes
// the final AO). One fetch per tap: the SSAO pass packs AO with 1/z and the tangent-plane
// slopes (ssao.comp). No shared memory: on llvmpipe every shared-memory access is gathered lane
// by lane and workgroup barriers are costly (a tiled single-dispatch version was twice as slow).
//
// Spatial weights: a box of width 2 radius with half-weight ends ([.5 1 1 1 .5] for radius 2).
// For even radii every phase of the 4x4 interleave pattern gets the same weight along each axis,
// so the pattern cancels exactly on flat regions.
// Edge stopping: a neighbour gets zero weight when its view distance differs by more than the
// tolerance (a fraction of the AO radius) from the centre's tangent plane extended to it; 1/z
// of a plane is affine in screen space, so the prediction is exact along a plane at any angle,
// and a surface across a depth discontinuity (or across a crease, once it leaves the plane) is
// rejected.
//
// Include after defining GI_BLUR_AXIS (0: x, 1: y) and declaring `outAO` (binding 3).
layout(local_size_x = 32, local_size_y = 16) in;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
// Keep in sync with gi::ssao::Uniforms (ssao_kernel.h).
layout(set = 0, binding = 1) uniform SsaoParams {
  vec4 params;   // radius, bias (world), intensity, blur depth tolerance (world)
  ivec4 counts;  // samples, blur radius
  vec4 rotation[16];
  uvec4 kernel[16];  // tap i: kernel[i / 4][i % 4], 11/11/10 bits (gi::ssao::packTap)
} ssao;
layout(set = 0, binding = 2) uniform sampler2D inAO;  // ao, 1/z (0: sky), d(1/z)/dx, d(1/z)/dy
// Blur radius, set at pipeline creation: the tap loop unrolls.
layout(constant_id = 0) const int kRadius = 2;  // 1..gi::ssao::kMaxBlurRadius

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  const ivec2 axis = GI_BLUR_AXIS == 0 ? ivec2(1, 0) : ivec2(0, 1);

  vec4 centre = texelFetch(inAO, p, 0);
  float ic = centre.y;
  float slope = GI_BLUR_AXIS == 0 ? centre.z : centre.w;
  float tol = ssao.params.w;
  float sum = centre.x, weights = 1.0;
  for (int o = -kRadius; o <= kRadius; ++o) {
    if (o == 0) continue;
    ivec2 q = p + o * axis;
    bool inside = q.x >= 0 && q.y >= 0 && q.x < size.x && q.y < size.y;
    vec4 t = texelFetch(inAO, clamp(q, ivec2(0), size - 1), 0);
    float iq = t.y;  // sky: 0, rejected below
    float pred = ic + slope * float(o);
    // |1/iq - 1/pred| < tol, without a division (iq, pred > 0).
    bool sameSurface = inside && pred > 0.0 && iq > 0.0 && abs(pred - iq) < tol * iq * pred;
    float w = sameSurface ? (abs(o) == kRadius ? 0.5 : 1.0) : 0.0;
    sum += w * t.x;
    weights += w;
  }
  // weights >= 1: the centre always counts. Guard: sky / far-plane pixels (1/z = 0) stay open.
  float ao = ic > 0.0 ? sum / weights : 1.0;
  imageStore(outAO, p, GI_BLUR_AXIS == 0 ? vec4(ao, centre.yzw) : vec4(ao));
}
