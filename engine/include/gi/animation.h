// Animation sampling, morph targets and the CPU reference skinning (the GPU skinning pass,
// engine/shaders/skinning.comp, does the same arithmetic).
#pragma once

#include <vector>

#include "gi/scene.h"

namespace gi {

// Value of a sampler at `time` (seconds, no looping: clamped to the first/last key).
// `rotation`: the values are quaternions (x, y, z, w): LINEAR slerps across the short arc,
// CUBICSPLINE renormalises. Returns `components` floats.
std::vector<float> sampleAnimation(const AnimationSampler& sampler, double time,
                                   bool rotation = false);

// The clip-local time of `time` for a clip looping over `duration` (deterministic fmod;
// negative times wrap too; duration <= 0 gives 0).
double loopTime(double time, double duration);

// Skinning matrices of the skinned node `node` (in the node's mesh space):
// inverse(node.world) * joint.world * inverseBindMatrix, one per joint of its skin. Empty
// when the node has no skin. Uses the current world transforms.
std::vector<glm::mat4> jointMatrices(const Scene& scene, int node);

// The blended skinning matrix of one vertex: sum(w_i * J_i) / sum(w_i); identity (bind pose)
// when the weights sum to zero or are not finite. Joint indices past `joints` count as zero.
glm::mat4 blendJoints(const std::vector<glm::mat4>& joints, const glm::uvec4& index,
                      const glm::vec4& weight);

// CPU reference skinning: positions by the blended matrix, normals by its cofactor
// (finite for singular matrices), normalised, falling back to the rest normal when the
// result vanishes. `rest` is parallel to mesh.joints/weights (the mesh's own vertices or a
// morphed copy). Rigid meshes are copied unchanged.
std::vector<Vertex> skinVertices(const Mesh& mesh, const std::vector<Vertex>& rest,
                                 const std::vector<glm::mat4>& joints);

// Mesh vertices with morph targets applied (position and normal deltas scaled by `weights`;
// missing weights count as 0), normals renormalised. Meshes without targets are returned as is.
std::vector<Vertex> morphVertices(const Mesh& mesh, const std::vector<float>& weights);

// Cofactor of the upper 3x3, signed by the determinant (normal transform that stays finite
// for singular matrices).
glm::mat3 cofactor3(const glm::mat4& m);

}  // namespace gi
