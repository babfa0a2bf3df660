// Shared by the ISM shaders: the parameter block (C++ mirror gi::ism::Uniforms in
// ism_params.h), the VPL table and the paraboloid mapping (the same basis as
// SceneView::paraboloid, so ISMs and the classic maps share texels).
#ifndef ISM_COMMON_GLSL
#define ISM_COMMON_GLSL

const uint ISM_EMPTY = 0xffffffffu;  // an ISM texel no point reached
const int ISM_VPL_SLOTS = 1024 + 64;   // gi::ism::kVplSlots

layout(set = 0, binding = 1, std140) uniform IsmParams {
  vec4 rsm;     // width, height, vpl count, padded count
  vec4 atlas;   // tile resolution, tiles per row, points per ISM, surface point count
  vec4 bias;    // constant (world), slope, near, far (classic maps)
  vec4 pull;    // pull threshold, push threshold, levels, scene extent
  vec4 gather;  // d_min^2, block k, k^2, strength
  vec4 blur;    // plane tolerance, min normal cosine, splat scale, VPLs of all bounces
  vec4 envSphere;  // environment VPLs' orthographic maps: centre, half side R (fitted to the view)
  vec4 envVpls;    // environment VPLs: count, padded count, first tile, normal offset (texels)
  vec4 nearField;  // range (world) of x: the "ao" darkening the environment VPLs' light, y: the
                   // earlier "indirect" the first bounce's far field is added to
  vec4 envDepth;   // x: the orthographic maps' depth origin beyond envSphere's centre
} ism;

// One VPL: position (w 1: valid), normal, flux (rgb, W).
struct Vpl {
  vec4 position;
  vec4 normal;
  vec4 flux;
};

void ismBasis(vec3 n, out vec3 s, out vec3 u) {
  vec3 up = abs(n.y) > 0.99 ? vec3(0.0, 0.0, 1.0) : vec3(0.0, 1.0, 0.0);
  s = normalize(cross(n, up));
  u = cross(s, n);
}

// First texel of tile `tile`. Row and column in float (exact below 2^24): llvmpipe divides
// integers lane by lane (a scalar division per lane).
ivec2 ismTileOrigin(uint tile) {
  float row = floor((float(tile) + 0.5) / ism.atlas.y);
  return ivec2(vec2(float(tile) - row * ism.atlas.y, row) * ism.atlas.x);
}

// Texel of direction `dir` (unit, cosine c = dot(dir, n) > 0) in tile `tile` of the atlas.
ivec2 ismTexel(uint tile, vec3 dir, vec3 s, vec3 u, float c) {
  vec2 p = vec2(dot(dir, s), dot(dir, u)) / max(1.0 + c, 1e-6);
  int res = int(ism.atlas.x);
  ivec2 t = clamp(ivec2((p * 0.5 + 0.5) * float(res)), ivec2(0), ivec2(res - 1));
  return ismTileOrigin(tile) + t;
}

// Environment VPL (direction d to the sky): its orthographic map looks along -d at the scene's
// bounding sphere (centre c, radius R), basis s, u = ismBasis(-d) (the view's x and y, as a
// paraboloid's around its axis). Texel of position p in tile `tile`, and p's depth
// R - (p - c).d: 0 on the sphere's sky side, 2R on the far side.
ivec2 ismOrthoTexel(uint tile, vec3 p, vec3 s, vec3 u) {
  vec3 q = p - ism.envSphere.xyz;
  vec2 disk = vec2(dot(q, s), dot(q, u)) / max(ism.envSphere.w, 1e-30);
  int res = int(ism.atlas.x);
  ivec2 t = clamp(ivec2((disk * 0.5 + 0.5) * float(res)), ivec2(0), ivec2(res - 1));
  return ismTileOrigin(tile) + t;
}
// Inside the map's square (the fitted region: gi::ism::fitEnvironmentMaps)?
bool ismOrthoInside(vec3 p, vec3 s, vec3 u) {
  vec3 q = p - ism.envSphere.xyz;
  return max(abs(dot(q, s)), abs(dot(q, u))) <= ism.envSphere.w;
}
float ismOrthoDepth(vec3 p, vec3 d) { return ism.envDepth.x - dot(p - ism.envSphere.xyz, d); }
float ismOrthoTexelSide() { return 2.0 * ism.envSphere.w / ism.atlas.x; }  // world units

uint ismHash(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

#endif
