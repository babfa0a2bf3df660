// One draw's material as the per-material uniform block of the scene draws (gbuffer.frag,
// scene_rsm.frag; filled by SceneGpu in engine/src/render/scene_gpu.cpp). Read uniformly in the
// fragment shader: neither a per-lane buffer load nor flat varyings per vertex.
#ifndef GI_MATERIAL_GLSL
#define GI_MATERIAL_GLSL

layout(set = 0, binding = 2) uniform MaterialBlock {
  vec4 baseColor;  // linear rgba
  vec4 emission;   // rgb radiance, 1
  vec4 params;     // roughness, metallic (both clamped to [0, 1]), textured (1/0),
                   // double-sided emission (1/0)
} material;

#endif
