// The engine's depth-aware (cross-bilateral) separable blur of one value per pixel
// (gi/depth_aware_blur.h), and the packing its producers write.
//
// Producers (an effect's compute pass) write an RGBA32F texel per pixel:
//   imageStore(out, p, depthAwareBlurPack(frame, value, P, N));
// with P the view-space position and N the view-space unit normal (a sky pixel: P = vec3(0)).
// The blur then reads one texel per tap. A producer at a reduced resolution writes
// depthAwareBlurPackScaled. Include after common.glsl.
//
// Blur weights: a box of width 2 radius with half-weight ends ([.5 1 1 1 .5] for radius 2), so
// for even radii every phase of a 4x4 interleave pattern gets the same weight along each axis
// and the pattern cancels exactly on flat regions. Edge stopping: a neighbour gets zero weight
// when its view distance differs by more than the tolerance (world units) from the centre's
// tangent plane extended to it; 1/z of a plane is affine in screen space, so the prediction is
// exact along a plane at any angle, and a surface across a depth discontinuity (or a crease,
// once it leaves the plane) is rejected.
#ifndef GI_DEPTH_AWARE_BLUR_GLSL
#define GI_DEPTH_AWARE_BLUR_GLSL

// value, 1 / view distance (0: sky, never averaged), and the tangent plane's d(1/z)/dpixel
// along x and y: on the plane N.X = K, 1/z = (N.D) / K along the view rays D (z = -1).
vec4 depthAwareBlurPack(FrameUniforms f, float value, vec3 P, vec3 N) {
  float dist = -P.z;
  if (!(dist > 0.0) || isinf(dist)) return vec4(value, 0.0, 0.0, 0.0);
  float iz = 1.0 / dist;
  vec3 D = P * iz;
  float nd = dot(N, D);
  // Guards: a degenerate projection does not divide by zero; a grazing normal (N.D near 0)
  // predicts nothing (slope 0: only neighbours at the centre's own distance are averaged).
  vec2 p = vec2(f.proj[0][0], f.proj[1][1]);
  p = vec2(abs(p.x) > 1e-30 ? p.x : 1e-30, abs(p.y) > 1e-30 ? p.y : 1e-30);
  vec2 dD = 2.0 * f.viewport.zw / p;
  vec2 slopes = nd < -1e-4 * length(D) ? iz * N.xy * dD / nd : vec2(0.0);
  return vec4(value, iz, slopes);
}

// The neighbour `o` pixels along `axis` from p, clamped into the image; `inside`: it was in it
// (a clamped tap is fetched, for a uniform loop, and given no weight).
ivec2 depthAwareBlurTap(ivec2 p, int o, ivec2 axis, ivec2 size, out bool inside) {
  ivec2 q = p + o * axis;
  inside = q.x >= 0 && q.y >= 0 && q.x < size.x && q.y < size.y;
  return clamp(q, ivec2(0), size - 1);
}

// The blur's weight of the neighbour `o` pixels along the axis (0 < |o| <= radius): the box's
// (half at the ends) when its 1 / view distance `iq` lies within `tol` (world units) of the
// centre's tangent plane (1 / view distance `ic`, `slope` d(1/z)/dpixel along the axis), else 0.
// |1/iq - 1/pred| < tol without a division (iq, pred > 0): sky (iq = 0) and a plane that does not
// reach the neighbour (pred <= 0) get no weight. Effects with a blur of their own share it.
float depthAwareBlurWeight(int o, int radius, float ic, float slope, float iq, float tol) {
  float pred = ic + slope * float(o);
  bool samePlane = pred > 0.0 && iq > 0.0 && abs(pred - iq) < tol * iq * pred;
  return samePlane ? (abs(o) == radius ? 0.5 : 1.0) : 0.0;
}

// The texel of a producer at 1 / scale of the frame's resolution (gi::DepthAwareBlur's
// `scale`): P and N are those of the frame pixel it stands for, the slopes per low-resolution
// pixel.
vec4 depthAwareBlurPackScaled(FrameUniforms f, float value, vec3 P, vec3 N, int scale) {
  vec4 t = depthAwareBlurPack(f, value, P, N);
  return vec4(t.xy, t.zw * float(scale));
}

#endif
