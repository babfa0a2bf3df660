// The per-view record of GpuScene's depth and reflective-shadow-map draws (one uniform slot per
// view; see engine/src/render/scene_gpu.cpp). Keep in sync with DrawViewUniforms there.
#ifndef GI_SCENE_VIEW_GLSL
#define GI_SCENE_VIEW_GLSL

struct DrawView {
  mat4 view;           // world -> view space
  mat4 proj;           // view -> clip, reverse-Z (perspective/orthographic)
  vec4 params;         // projection (0 perspective, 1 orthographic, 2 paraboloid), near, far, 0
  vec4 lightPosType;   // RSM: world position, type (0 directional, 1 point, 2 spot)
  vec4 lightDirRange;  // RSM: world direction the light points to, range (0: infinite)
  vec4 lightRadiance;  // RSM: colour x intensity
  vec4 lightCone;      // RSM: cos inner, cos outer, world area of a texel (orthographic), 0
  vec4 viewport;       // x, y, width, height of the view in its target, in pixels
};

// Clip position of a world point. Paraboloid: the hemisphere around the view's -z axis maps to
// the unit disk (p = dir.xy / (1 + cos)), depth is the radial distance, reverse-Z between near
// and far; `clipDistance` < 0 behind the hemisphere.
vec4 projectWorld(DrawView v, vec3 world, out float clipDistance) {
  vec4 viewPos = v.view * vec4(world, 1.0);
  clipDistance = 1.0;
  if (v.params.x < 1.5) return v.proj * viewPos;
  float d = length(viewPos.xyz);
  vec3 u = d > 1e-20 ? viewPos.xyz / d : vec3(0.0, 0.0, -1.0);  // guard: a point at the centre
  float c = -u.z;  // cosine to the axis
  clipDistance = c;
  vec2 p = u.xy / max(1.0 + c, 1e-6);
  float depth = 1.0 - (d - v.params.y) / max(v.params.z - v.params.y, 1e-20);
  return vec4(p, depth, 1.0);
}

#endif
