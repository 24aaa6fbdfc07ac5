// Skins and morph targets at the pose a glTF viewer shows without animation (internal to the loader):
// morph targets at their default weights (node.weights, else mesh.weights; glTF 2.0 §3.7.2.2), then linear
// blend skinning with the joints' node transforms (§3.7.3: jointMatrix = world(joint) x inverseBindMatrix;
// the skinned mesh node's own transform is ignored, so skinned vertices come out in world space).
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "engine/scene/mesh_builder.h"

namespace tinygltf {
class Model;
struct Primitive;
} // namespace tinygltf

namespace nbvh::gltf {

struct Pose {
    std::vector<float> weights;     // morph target weights (empty: no morphing)
    std::vector<glm::dmat4> joints; // joint matrices (empty: not skinned)
    // Skinned vertices without any joint influence (weights summing to 0, or only invalid joints) are
    // placed by this transform: the node's world transform, as if the mesh were not skinned.
    glm::dmat4 unskinned{1.0};
    bool skinned() const { return !joints.empty(); }
    bool morphed() const; // some weight is non-zero
};

// Joint matrices of skin `skin` from the nodes' world transforms (`world_valid[n]` false: non-finite).
// Returns false (with a warning naming the skin and the problem, for `what`) when the skin cannot be
// used: a joint that does not exist or has a non-finite transform, unreadable inverseBindMatrices.
bool skin_joints(const tinygltf::Model& model, int skin, const std::vector<glm::dmat4>& world,
                 const std::vector<uint8_t>& world_valid, std::vector<glm::dmat4>& joints,
                 const std::string& what);

// Default morph weights of mesh `mesh` on node `node` (node.weights, else mesh.weights; node -1: the
// mesh's; non-finite -> 0). Targets beyond the list have weight 0.
std::vector<float> morph_weights(const tinygltf::Model& model, int node, int mesh);

// Applies `pose` to one decoded primitive (positions, normals, tangents; same vertex order as `prim`'s
// attributes): morph targets, then skinning. Attributes of the wrong length are ignored with a warning.
void apply_pose(const tinygltf::Model& model, const tinygltf::Primitive& prim, const Pose& pose,
                PrimitiveData& d, const std::string& what);

} // namespace nbvh::gltf
