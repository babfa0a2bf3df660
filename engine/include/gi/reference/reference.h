// CPU ground-truth renderer (Embree ray tracing, no Vulkan). For the scene, camera and pixel
// convention of the Vulkan renderer it estimates, per pixel, the quantity a screen-space effect
// approximates, together with its own standard error:
//
//  - The camera is gi::activeCamera(scene, width / height). Pixel (x, y) is sampled at its
//    centre: uv = ((x + 0.5) / w, (y + 0.5) / h), y down, NDC = uv * 2 - 1, and the primary ray
//    runs from the camera through the inverse projection of that NDC point, between the near
//    and far planes (what the rasteriser keeps). There is no antialiasing: every quantity is
//    the one at the surface point a deferred renderer stores for that pixel, so reference and
//    effect images compare pixel by pixel.
//  - Surfaces are double-sided like the rasteriser's (no culling; normals face the viewer).
//
// Quantities (n: the G-buffer normal, i.e. the interpolated vertex normal facing the viewer;
// t(w): distance to the first surface along direction w; integrals over the hemisphere of n):
//  - AO (RTR eq. 11.8 with a distance limit r):  k_A = (1/pi) int V_r(w) cos(theta) dw, where
//    V_r = 0 if something is hit within r, else 1. 1 = fully open.
//  - Obscurance (seed 001 eq. 5):  O = (1/pi) int mu(t(w)) cos(theta) dw, mu a membership
//    function reaching 1 at distance R = r (a miss counts 1).
//  - Alchemy (seed 003): the integral the Alchemy AO estimator claims to estimate, see below.
//  - Direct: L = Le + sum over point/spot/directional lights of f_r(l, v) E_l cos V_l (the
//    rasteriser's light units and falloffs, plus a shadow ray) + (rho/pi) int L_env(w) V(w) cos
//    dw (the procedural sky or constant environment, occluded by the scene). The BRDF is the
//    lighting pass's: f_r = rho/pi + f0 (s + 8)/(8 pi) max(n.h, 0)^s for the punctual lights
//    (rho = albedo * (1 - metallic), f0 = mix(0.04, albedo, metallic), s the Blinn-Phong
//    exponent of the roughness, lights.glsl shininessOf; v towards the eye), Lambert alone for
//    the environment and for indirect light (the renderer has no specular term for them).
//    Le only where the emitter is seen from its front side: the side its interpolated normal
//    points to, or either side when the material is double-sided (the rasteriser's rule).
//  - DirectIndirect: Direct + one diffuse bounce: (rho/pi) int L_1(y(w)) cos dw over the
//    directions that hit a surface y, where L_1(y) = Le(y) + Direct-without-Le at y, i.e.
//    emissive surfaces count as light sources here (only here: Direct ignores them as lights).
//    An emitter lights only its front side unless its material is double-sided. A bounce vertex
//    y reflects the punctual lights with the same BRDF towards the previous vertex.
//  - Depth, Normal: the primary hit (deterministic, one sample).
//  - AOSplit ("ao-split"): AO as above, with its occlusion split by what a single-layer screen-
//    space method can see. Each occluded direction of the AO estimator (something within r) is
//    put in exactly one class:
//      visible:    some surface of the depth layer lies on the ray within r. The depth layer is
//                  the set of primary hits this renderer traces (the same camera, pixel centres
//                  and [znear, zfar] as the rasteriser's depth buffer). A ray point x, at view
//                  depth d, belongs to it when it projects inside the frame and, for its pixel
//                  or one of the 8 around it, |d - D| <= 0.01 d + 0.001 r, where D is that
//                  pixel's primary view depth or the depth at which the ray from the eye through
//                  x meets that pixel's primary tangent plane (point + geometric normal; exact
//                  for planes seen at grazing angles). The first hit is tested first; when it is
//                  not in the layer the ray goes on (up to r) through later hits: a depth-buffer
//                  method does not know about a surface in front of a layer surface it sees.
//      off-screen: otherwise, if the first hit lies outside the view frustum: outside the
//                  image, behind the camera, nearer than znear or beyond zfar.
//      hidden:     otherwise: the first hit projects inside the frame but is not in the depth
//                  layer, i.e. lies behind the visible surface there (or, rarely, is sub-pixel
//                  geometry between pixel centres in front of it; Result::splitHiddenInFront
//                  counts those rays).
//    Per pixel: AO_full (= AO; the value image), the fractions f_vis, f_off, f_hid of the
//    cosine-weighted hemisphere occluded by each class, and AO_visible = 1 - f_vis, the AO of
//    the depth layer alone (non-layer surfaces transparent): what a single-layer screen-space
//    estimator can at best converge to. Per sample the four indicators sum to 1, so
//    1 - AO_full = f_vis + f_off + f_hid holds per pixel up to float rounding. The samples are
//    the AO quantity's (same seed, same directions, closest instead of any hit), so AO_full and
//    its standard error equal the AO quantity's bit for bit.
//
// Estimators: i.i.d. cosine-weighted directions (pdf cos/pi), one per sample; each sample
// reuses the pixel's deterministic light terms. The light of emissive surfaces in
// DirectIndirect is estimated both by that direction and by a point sampled on the emitters
// (triangle chosen by area * luminance, uniform on it, shadow ray), combined by multiple
// importance sampling with the balance heuristic: small bright emitters converge fast, and
// points very close to an emitter do not blow up. Each sample's random numbers come from
// (seed, pixel, sample index) only, so an image is identical for any thread count. The
// standard error is sqrt(s^2 / n) from the per-pixel sample variance s^2 (Welford, double).
// A pixel whose samples are all equal reports 0 even if its expectation lies between (e.g.
// AO near 1 with few samples): read it together with the sample count.
//
// What the Alchemy estimator estimates. Seed 003 eq. 4 defines obscurance with a falloff g as
//   A = 1 - (1/pi) int [1 - V(c, c + w min(t(w) + eps, r))] g(t(w)) (w.n) dw,
// which, the visibility term being 0 exactly on the set Gamma of directions whose first hit is
// nearer than r, is eq. 6:  A = 1 - (1/pi) int_Gamma g(t(w)) (w.n) dw.  With the falloff
// g(t) = u t / max(u, t)^2 and v = t w this is eq. 8, A = 1 - (u/pi) int_Gamma (v.n)/max(u^2,
// v.v) dw; sampling w uniformly on the hemisphere (pdf 1/(2 pi)) gives eq. 9,
// 1 - (2u/s) sum max(0, v_i.n) H(r - |v_i|) / max(u^2, v_i.v_i), whose expectation is exactly
// eq. 8. Eq. 10 then replaces u in the numerator by the intensity sigma and max(u^2, v.v) by
// v.v + epsilon, drops the Heaviside in favour of sampling within the radius, adds the bias
// beta (a depth-precision concession, 0 here) and applies max(0, .)^k. So, for a sample set
// that is uniform in direction, the sum in eq. 10 estimates
//   I = (1/pi) int_Gamma g(t(w)) cos(theta) dw,  g(t) = sigma t / (max(u^2, t^2) + epsilon)
// (u = 0 for eq. 10; sigma = u, epsilon = 0 for eq. 7-9), and the effect's output claims
// A = max(0, 1 - I)^k. This renderer computes I by cosine-weighted sampling (I = E[g(t) H(r -
// t)] over cos-distributed w) and reports A = max(0, 1 - mean)^k, with the standard error
// propagated through the derivative k (1 - I)^(k - 1). Two things the screen-space estimator
// does differently are not part of the claim and show up as its error: (1) its samples are
// points on a disk of radius r in the image plane read back from the depth buffer, not
// directions uniform on the hemisphere, so its expectation weights the hemisphere differently
// (and sees only the depth layer); (2) it applies max(0, .)^k per pixel to a finite-sample
// sum, and E[max(0, 1 - X)^k] != max(0, 1 - E[X])^k.
//
// What the Alchemy estimator's sum really converges to (AlchemyDisk, "alchemy-disk"; see
// effects/alchemy/README.md). Eq. 10's taps are uniform in radius and angle on the screen-space
// disk that the world radius r projects to at the pixel's depth, read back from the depth
// buffer, with no Jacobian. Its expectation is the screen-disk integral
//   I_disk = (sigma / (pi r)) int_0^r int_0^2pi max(0, v.n - beta z) H(r - |v|)
//                                               / (max(u^2, v.v) + epsilon) dphi drho
// and this quantity estimates exactly that: for the primary hit C (view-space position c,
// view depth z = -c.z, G-buffer normal n) a sample draws rho uniform in [0, r) and phi uniform
// in [0, 2 pi), forms the point X = c + rho (cos phi, sin phi, 0) in the camera-facing plane
// through C (view space: x right, y up), traces the camera ray through X (perspective: from the
// eye; orthographic: along the view axis) between znear and zfar to its first hit P (the depth
// layer: what the depth buffer holds at X's pixel), and scores 2 sigma max(0, v.n - beta z)
// H(r^2 - v.v) / (max(u^2, v.v) + epsilon) with v = P - C in view space (0 when the ray misses:
// sky). The pixel reports A = max(0, 1 - mean)^k like Alchemy. The conventions are
// alchemy_kernel.h's (u = 0 there): view-space lengths, bias proportional to the view depth,
// the strict v.v < r^2. Differences from the plugin that are not part of the quantity: the
// plugin's taps are a fixed spiral snapped to texel centres (a quadrature, not i.i.d. points),
// taps off the image count as unoccluded unless its guard band covers them (here the guard band
// is unlimited: every tap is traced), and it clamps the disk's projected radius to the image
// size (a camera inside the ball).
//
// Cameras: Settings::camera, when set, replaces gi::activeCamera (tests use it for exact views).
// Its projection may be orthographic (proj[3][3] == 1, e.g. gi::orthoReverseZ): primary rays
// then run along the view axis; AOSplit needs a perspective camera (it measures along eye rays).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "gi/image_io.h"
#include "gi/reference/sampling.h"
#include "gi/scene.h"

namespace gi::reference {

// The estimators' version: bumped whenever a quantity's definition or estimator changes, so
// that results cached from an older one (gi-bench's reference cache) are not reused.
// 2: the lighting pass's Blinn-Phong lobe for the punctual lights; one-sided emitters.
inline constexpr int kVersion = 2;

enum class Quantity {
  AO,
  Obscurance,
  Alchemy,
  Direct,
  DirectIndirect,
  Depth,
  Normal,
  AOSplit,
  AlchemyDisk
};

// Command-line names: ao, obscurance, alchemy, direct, direct+indirect, depth, normal, ao-split,
// alchemy-disk;
// memberships: sqrt, linear, smoothstep, step, exp. Throw gi::Error(Usage) for unknown names.
Quantity parseQuantity(const std::string& name);
const char* quantityName(Quantity q);
Membership parseMembership(const std::string& name);
const char* membershipName(Membership m);

struct Progress {
  uint32_t spp = 0;           // samples per pixel so far
  double meanStdError = 0.0;  // over geometry pixels
  double seconds = 0.0;       // since the start of render()
};

inline constexpr uint32_t kMaxBounces = 8;  // Settings::bounces

struct Settings {
  uint32_t width = 320, height = 240;
  Quantity quantity = Quantity::AO;
  float radius = 0.5f;  // AO / AO split radius r, obscurance R, Alchemy (disk) r (world units)
  Membership membership = Membership::Sqrt;
  AlchemyParams alchemy;
  uint32_t spp = 64;  // maximum samples per pixel
  // DirectIndirect: diffuse bounces after the direct light (1..kMaxBounces). Beyond the first,
  // each bounce vertex continues the cosine-sampled path (emitters met on it unweighted: only
  // the first vertex samples them directly).
  uint32_t bounces = 1;
  // DirectIndirect: emissive surfaces light the others (true), or are only seen (false: what a
  // renderer whose effects take light only from the scene's lights computes; the emitters'
  // own pixels keep their radiance).
  bool emitterLight = true;
  double noiseTarget = 0.0;  // > 0: stop once the mean standard error is at most this
  uint32_t minSpp = 16;      // samples before the noise target is first checked
  uint64_t seed = 1;
  std::optional<CameraView> camera;  // replaces activeCamera(scene, width / height) when set
  unsigned threads = 0;              // 0: std::thread::hardware_concurrency()
  std::function<void(const Progress&)> progress;  // called after each progressive pass
};

struct Result {
  // The quantity (rgb; scalar quantities repeated in rgb), alpha 1 on geometry, 0 on sky. Sky
  // pixels hold 1 for the AO-like quantities (fully open), the environment radiance for the
  // lighting quantities, and 0 for depth/normal.
  ImageRGBA32F value;
  ImageRGBA32F stdError;  // per-pixel standard error of `value` (rgb), alpha as in value
  // The primary hits, in the Vulkan renderer's conventions (all 0 on sky pixels):
  ImageRGBA32F depth;     // r: reverse-Z NDC depth (1 near, 0 far; 0 = sky, the clear value),
                          // g: view-space z (negative in front of the camera), b: 1 on geometry,
                          // 0 on sky (the sky mask, kept in 3-channel PFM files), a: same
  ImageRGBA32F normal;    // view-space normal facing the camera (the G-buffer's), a: mask
  ImageRGBA32F position;  // world-space position, a: mask
  // AOSplit only (empty otherwise): r = AO_visible, g = off-screen occluded fraction f_off,
  // b = hidden occluded fraction f_hid, a = mask; sky pixels (1, 0, 0, 0). The value image holds
  // AO_full, so the visible-occluded fraction is f_vis = 1 - AO_visible = 1 - AO_full - f_off -
  // f_hid. splitStdError: the per-pixel standard errors of r, g and b.
  ImageRGBA32F split;
  ImageRGBA32F splitStdError;
  // AOSplit diagnostics, summed over all samples of all pixels: occluded rays; rays counted
  // visible although their first hit was not in the depth layer (a layer surface further on
  // within r); rays counted hidden whose first hit lies in front of the depth layer at its pixel
  // (or projects onto sky), i.e. sub-pixel geometry rather than a surface behind the layer.
  uint64_t splitOccluded = 0, splitVisibleBehind = 0, splitHiddenInFront = 0;
  CameraView camera;
  uint32_t spp = 0;           // samples per pixel reached (1 for depth/normal)
  double meanStdError = 0.0;  // mean over geometry pixels of the per-pixel error (mean of rgb;
                              // for AOSplit that of AO_full)
  double seconds = 0.0;       // wall time of render() (including the BVH build)
  size_t geometryPixels = 0;
  size_t triangles = 0;
};

// Renders `scene` as it stands (world transforms as updated by the caller, e.g. after
// Scene::animate(time)). Throws gi::Error(Usage) for invalid settings.
Result render(const Scene& scene, const Settings& settings);

// The procedural sky / constant environment radiance in world direction `dir` (unit), the
// same function as environmentRadiance in engine/shaders/common.glsl.
glm::vec3 environmentRadiance(const Environment& env, const glm::vec3& dir);

// Per-pixel planes of an AOSplit result over its geometry pixels, and their means.
struct AoSplitSummary {
  size_t pixels = 0;                                    // geometry pixels
  double aoFull = 0.0, aoVisible = 0.0;                 // means
  double visible = 0.0, offscreen = 0.0, hidden = 0.0;  // mean occluded fractions
  double limitNrmse = 0.0;  // RMS(AO_visible - AO_full) / mean(AO_full) (0 when no pixel)
};
AoSplitSummary summarizeAoSplit(const Result& r);

// 8-bit preview: AO-like quantities as grey, lighting with the renderer's tonemap (exposure,
// ACES fit, sRGB), depth as grey NDC depth, normals as n * 0.5 + 0.5.
ImageRGBA8 preview(const ImageRGBA32F& value, Quantity q, float exposure = 1.0f);
// 8-bit grey preview of channel c (0..2) of an image (values clamped to [0, 1]), e.g. the
// fractions of Result::split.
ImageRGBA8 previewChannel(const ImageRGBA32F& image, int c);

}  // namespace gi::reference
