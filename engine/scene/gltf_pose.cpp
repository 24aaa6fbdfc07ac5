#include "engine/scene/gltf_pose.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include <glm/gtc/type_ptr.hpp>
#include <tiny_gltf.h>

#include "engine/core/log.h"
#include "engine/scene/gltf_accessor.h"

namespace nbvh::gltf {
namespace {

bool finite_matrix(const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

int attribute(const std::map<std::string, int>& attributes, const std::string& key) {
    auto a = attributes.find(key);
    return a == attributes.end() ? -1 : a->second;
}

// Accessor `index` as `n` vectors of `comps` floats, or empty (warned) when its length is not n.
std::vector<float> read_per_vertex(const tinygltf::Model& model, int index, int comps, size_t n,
                                   const std::string& what) {
    std::vector<float> v = read_floats(model, index, comps, what);
    if (v.size() == n * size_t(comps)) return v;
    log_warn("%s has %zu elements for %zu vertices; ignored", what.c_str(), v.size() / size_t(comps), n);
    return {};
}

void morph(const tinygltf::Model& model, const tinygltf::Primitive& prim, const std::vector<float>& weights,
           PrimitiveData& d, const std::string& what) {
    const size_t n = d.positions.size();
    const size_t targets = std::min(weights.size(), prim.targets.size());
    for (size_t t = 0; t < targets; ++t) {
        const float w = weights[t];
        if (w == 0.0f) continue;
        const std::map<std::string, int>& target = prim.targets[t];
        const std::string wt = what + strfmt(" target %zu", t);
        if (int a = attribute(target, "POSITION"); a >= 0) {
            const std::vector<float> delta = read_per_vertex(model, a, 3, n, wt + " POSITION");
            for (size_t i = 0; i < n && !delta.empty(); ++i)
                d.positions[i] += w * glm::make_vec3(&delta[3 * i]);
        }
        if (int a = attribute(target, "NORMAL"); a >= 0 && d.normals.size() == n) {
            const std::vector<float> delta = read_per_vertex(model, a, 3, n, wt + " NORMAL");
            for (size_t i = 0; i < n && !delta.empty(); ++i)
                d.normals[i] += w * glm::make_vec3(&delta[3 * i]);
        }
        if (int a = attribute(target, "TANGENT"); a >= 0 && d.tangents.size() == n) { // xyz deltas only
            const std::vector<float> delta = read_per_vertex(model, a, 3, n, wt + " TANGENT");
            for (size_t i = 0; i < n && !delta.empty(); ++i)
                d.tangents[i] += glm::vec4(w * glm::make_vec3(&delta[3 * i]), 0.0f);
        }
    }
}

void skin(const tinygltf::Model& model, const tinygltf::Primitive& prim, const Pose& pose, PrimitiveData& d,
          const std::string& what) {
    const size_t n = d.positions.size();
    // The JOINTS_k / WEIGHTS_k sets, 4 influences per vertex each.
    std::vector<std::pair<std::vector<float>, std::vector<float>>> sets;
    for (int set = 0;; ++set) {
        const int ja = attribute(prim.attributes, strfmt("JOINTS_%d", set));
        const int wa = attribute(prim.attributes, strfmt("WEIGHTS_%d", set));
        if (ja < 0 || wa < 0) break;
        std::vector<float> joints = read_per_vertex(model, ja, 4, n, what + strfmt(" JOINTS_%d", set));
        std::vector<float> weights = read_per_vertex(model, wa, 4, n, what + strfmt(" WEIGHTS_%d", set));
        if (!joints.empty() && !weights.empty()) sets.emplace_back(std::move(joints), std::move(weights));
    }
    size_t bad_joints = 0, unskinned = 0;
    for (size_t i = 0; i < n; ++i) {
        glm::dmat4 sum(0.0);
        double total = 0.0;
        for (const auto& [joints, weights] : sets)
            for (size_t k = 4 * i; k < 4 * i + 4; ++k) {
                const double w = weights[k];
                if (!(w > 0.0) || !std::isfinite(w)) continue;
                if (!(joints[k] >= 0.0f && joints[k] < float(pose.joints.size()))) {
                    ++bad_joints;
                    continue;
                }
                sum += w * pose.joints[size_t(joints[k])];
                total += w;
            }
        // Weights should sum to 1 (glTF 2.0 §3.7.3.3): renormalised; a vertex without any influence is
        // placed as the unskinned node would place it.
        const glm::dmat4 s = total > 0.0 ? sum / total : pose.unskinned;
        unskinned += !(total > 0.0);
        d.positions[i] = glm::vec3(s * glm::dvec4(glm::dvec3(d.positions[i]), 1.0));
        const glm::dmat3 l(s);
        if (i < d.normals.size()) {
            // Normals by the inverse transpose (non-uniform scale); a singular matrix leaves a normal that
            // build_mesh() repairs.
            const glm::dvec3 nrm = std::fabs(glm::determinant(l)) > 1e-300
                                       ? glm::transpose(glm::inverse(l)) * glm::dvec3(d.normals[i])
                                       : l * glm::dvec3(d.normals[i]);
            d.normals[i] = glm::vec3(nrm);
        }
        if (i < d.tangents.size())
            d.tangents[i] = glm::vec4(glm::vec3(l * glm::dvec3(glm::vec3(d.tangents[i]))), d.tangents[i].w);
    }
    if (bad_joints)
        log_warn("%s: %zu skin influences name a joint the skin does not have; ignored", what.c_str(),
                 bad_joints);
    if (unskinned)
        log_warn("%s: %zu vertices have no skin weight; placed by the node's transform", what.c_str(),
                 unskinned);
}

} // namespace

bool Pose::morphed() const {
    for (float w : weights)
        if (w != 0.0f) return true;
    return false;
}

bool skin_joints(const tinygltf::Model& model, int skin_index, const std::vector<glm::dmat4>& world,
                 const std::vector<uint8_t>& world_valid, std::vector<glm::dmat4>& joints,
                 const std::string& what) {
    joints.clear();
    if (skin_index < 0 || size_t(skin_index) >= model.skins.size()) {
        log_warn("%s: skin %d does not exist; rendered unskinned", what.c_str(), skin_index);
        return false;
    }
    const tinygltf::Skin& skin = model.skins[size_t(skin_index)];
    if (skin.joints.empty()) {
        log_warn("%s: skin %d has no joints; rendered unskinned", what.c_str(), skin_index);
        return false;
    }
    std::vector<float> inverse_bind;
    if (skin.inverseBindMatrices >= 0) {
        inverse_bind = read_floats(model, skin.inverseBindMatrices, 16,
                                   what + strfmt(" skin %d inverseBindMatrices", skin_index));
        if (inverse_bind.size() != 16 * skin.joints.size()) {
            log_warn("%s: skin %d has %zu inverse bind matrices for %zu joints; rendered unskinned",
                     what.c_str(), skin_index, inverse_bind.size() / 16, skin.joints.size());
            return false;
        }
    }
    for (size_t j = 0; j < skin.joints.size(); ++j) {
        const int node = skin.joints[j];
        if (node < 0 || size_t(node) >= world.size() || !world_valid[size_t(node)]) {
            log_warn("%s: skin %d joint %zu (node %d) does not exist or has a non-finite transform; rendered "
                     "unskinned",
                     what.c_str(), skin_index, j, node);
            joints.clear();
            return false;
        }
        // Absent inverseBindMatrices are identities (glTF 2.0 §5.27).
        const glm::dmat4 ibm =
            inverse_bind.empty() ? glm::dmat4(1.0) : glm::dmat4(glm::make_mat4(&inverse_bind[16 * j]));
        joints.push_back(world[size_t(node)] * ibm);
        if (!finite_matrix(joints.back())) {
            log_warn("%s: skin %d joint %zu has a non-finite joint matrix; rendered unskinned", what.c_str(),
                     skin_index, j);
            joints.clear();
            return false;
        }
    }
    return true;
}

std::vector<float> morph_weights(const tinygltf::Model& model, int node, int mesh) {
    const bool own = node >= 0 && !model.nodes[size_t(node)].weights.empty();
    const std::vector<double>& given =
        own ? model.nodes[size_t(node)].weights : model.meshes[size_t(mesh)].weights;
    std::vector<float> w(given.size(), 0.0f);
    for (size_t i = 0; i < given.size(); ++i) w[i] = std::isfinite(given[i]) ? float(given[i]) : 0.0f;
    return w;
}

void apply_pose(const tinygltf::Model& model, const tinygltf::Primitive& prim, const Pose& pose,
                PrimitiveData& d, const std::string& what) {
    if (pose.morphed() && !prim.targets.empty()) morph(model, prim, pose.weights, d, what);
    if (pose.skinned()) skin(model, prim, pose, d, what);
}

} // namespace nbvh::gltf
