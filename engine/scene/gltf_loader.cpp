#include "engine/scene/gltf_loader.h"

#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <set>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <tiny_gltf.h>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/scene/gltf_accessor.h"
#include "engine/scene/gltf_lights.h"
#include "engine/scene/gltf_material.h"
#include "engine/scene/gltf_pose.h"
#include "engine/scene/gltf_schema.h"
#include "engine/scene/gltf_support.h"
#include "engine/scene/mesh_builder.h"
#include "engine/scene/scene_stats.h"
#include "engine/scene/subdivide.h"

namespace nbvh {
namespace {

// World-space limit (metres): float32 ray-triangle and normal math overflows beyond ~1e9 (|x|^4 > 3.4e38).
constexpr float MAX_WORLD_COORDINATE = 1e9f;
// Vertices in per-node posed copies of skinned or morphed meshes (~2 GB of vertex data at most).
constexpr uint64_t MAX_POSED_VERTICES = uint64_t(1) << 25;

std::string first_line(const std::string& s) {
    std::string line = s.substr(0, s.find('\n'));
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    return line.empty() ? std::string("unknown error") : line;
}

bool is_neural_scene_name(const std::string& name) {
    const std::string suffix = "_neural";
    return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// tinygltf's default file callbacks open whatever a buffer or image URI names: a directory opens and reports
// a bogus size (std::bad_alloc on ext4, fuzz regression seed crash_buffer_uri_is_directory.gltf) and a FIFO
// blocks. Only regular files are files here.
bool regular_file(const std::string& path) {
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}
bool file_exists(const std::string& path, void*) { return regular_file(path); }
bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    if (!regular_file(path)) {
        if (err) *err += "not a regular file: " + path + "\n";
        return false;
    }
    return tinygltf::ReadWholeFile(out, err, path, user);
}

tinygltf::Model parse_file(const std::filesystem::path& path, bool keep_textures) {
    const std::string file = path.string();
    // A directory opens as an ifstream on Linux and tinygltf then sizes its read buffer from it (a huge
    // allocation), so refuse anything that is not a regular file up front; likewise other formats.
    std::error_code fs_ec;
    if (std::filesystem::is_directory(path, fs_ec))
        throw Error(strfmt("'%s' is a directory, not a scene file (.gltf or .glb)", file.c_str()));
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".gltf" && ext != ".glb")
        throw Error(strfmt("%s: unsupported scene format '%s' (expected .gltf or .glb)", file.c_str(), ext.c_str()));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(strfmt("cannot open scene file '%s'", file.c_str()));
    char magic[4] = {0, 0, 0, 0};
    in.read(magic, 4);
    const bool binary = in.gcount() == 4 && std::string(magic, 4) == "glTF";
    if (ext == ".glb" && !binary) {
        std::string shown;
        for (int i = 0; i < int(in.gcount()); ++i)
            shown += std::isprint(static_cast<unsigned char>(magic[i])) ? magic[i] : '?';
        throw Error(strfmt("%s: not a GLB file (magic '%s', expected 'glTF')", file.c_str(), shown.c_str()));
    }
    if (binary) {
        // GLB header (magic, version, total length): tinygltf's message for a cut file is only "Invalid glTF
        // binary", so say what is wrong here.
        uint32_t header[2] = {0, 0};
        in.read(reinterpret_cast<char*>(header), sizeof header);
        std::error_code ec;
        const uint64_t size = std::filesystem::file_size(path, ec);
        if (in.gcount() != sizeof header || ec)
            throw Error(strfmt("%s: truncated GLB (no complete 12-byte header)", file.c_str()));
        if (header[0] != 2)
            throw Error(strfmt("%s: unsupported GLB version %u (expected 2)", file.c_str(), header[0]));
        if (header[1] > size)
            throw Error(strfmt("%s: truncated GLB: header says %u bytes, file has %llu", file.c_str(), header[1],
                               (unsigned long long)size));
    }
    in.close();

    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks({&file_exists, &tinygltf::ExpandFilePath, &read_whole_file, &tinygltf::WriteWholeFile, nullptr});
    gltf::ImageDecodeContext images{keep_textures, 0};
    loader.SetImageLoader(gltf::decode_image, &images);
    tinygltf::Model model;
    std::string err, warn;
    const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, file)
                           : loader.LoadASCIIFromFile(&model, &err, &warn, file);
    // Before tinygltf's own error: a parse that failed on buffers only a required extension can decode
    // (meshopt fallback buffers have no uri) is explained by the extension.
    gltf::check_required_extensions(model.extensionsRequired, file);
    std::istringstream lines(warn);
    for (std::string line; std::getline(lines, line);)
        if (!line.empty()) log_warn("%s: %s", path.filename().string().c_str(), line.c_str());
    if (!ok) throw Error(strfmt("%s: %s", file.c_str(), first_line(err).c_str()));
    gltf::check_schema(path);
    return model;
}

// Node-local transform: `matrix` or T * R * S (glTF 2.0 §3.5.3). Returns false when non-finite.
bool local_transform(const tinygltf::Node& node, glm::dmat4& out) {
    out = glm::dmat4(1.0);
    if (node.matrix.size() == 16) {
        out = glm::make_mat4(node.matrix.data());
    } else {
        glm::dmat4 t(1.0), r(1.0), s(1.0);
        if (node.translation.size() == 3)
            t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
        if (node.rotation.size() == 4) {
            glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]); // (w, x, y, z)
            const double len = glm::length(q);
            if (len > 0.0 && std::isfinite(len)) r = glm::mat4_cast(q / len);
            else if (!std::isfinite(len)) return false;
        }
        if (node.scale.size() == 3) s = glm::scale(glm::dmat4(1.0), glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
        out = t * r * s;
    }
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(out[c][r])) return false;
    return true;
}

// Rejects out-of-range children and cycles over the whole node graph (iterative DFS, three colours), so the
// scene traversal below can never loop (bad/assimp/RecursiveNodes).
void check_node_graph(const tinygltf::Model& model, const std::string& file) {
    const size_t n = model.nodes.size();
    for (size_t i = 0; i < n; ++i)
        for (int c : model.nodes[i].children)
            if (c < 0 || size_t(c) >= n)
                throw Error(strfmt("%s: node %zu has child %d which does not exist (%zu nodes)", file.c_str(), i, c, n));
    std::vector<uint8_t> colour(n, 0); // 0 = unvisited, 1 = on the current path, 2 = done
    std::vector<std::pair<size_t, size_t>> stack; // (node, next child)
    for (size_t root = 0; root < n; ++root) {
        if (colour[root]) continue;
        stack.push_back({root, 0});
        colour[root] = 1;
        while (!stack.empty()) {
            auto& [node, next] = stack.back();
            const std::vector<int>& children = model.nodes[node].children;
            if (next == children.size()) {
                colour[node] = 2;
                stack.pop_back();
                continue;
            }
            const size_t child = size_t(children[next++]);
            if (colour[child] == 1)
                throw Error(strfmt("%s: node cycle: node %zu ('%s') is its own ancestor (via node %zu)", file.c_str(),
                                   child, model.nodes[child].name.c_str(), node));
            if (colour[child] == 0) {
                colour[child] = 1;
                stack.push_back({child, 0});
            }
        }
    }
}

const char* mode_name(int mode) {
    switch (mode) {
    case TINYGLTF_MODE_POINTS: return "POINTS";
    case TINYGLTF_MODE_LINE: return "LINES";
    case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
    default: return "unknown";
    }
}

template <int N, class V>
std::vector<V> to_vectors(const std::vector<float>& flat) {
    std::vector<V> out(flat.size() / N);
    for (size_t i = 0; i < out.size(); ++i)
        for (int c = 0; c < N; ++c) out[i][c] = flat[i * N + c];
    return out;
}

class Loader {
public:
    Loader(const std::filesystem::path& path, const SceneLoadOptions& options)
        : path_(path), file_(path.filename().string()), options_(options) {}

    Scene load() {
        model_ = parse_file(path_, options_.keep_textures);
        gltf::warn_ignored_features(model_, file_);
        scene_.source = path_.string();
        default_material_ = gltf::convert_materials(model_, options_.keep_textures, scene_);
        check_node_graph(model_, file_);
        const std::vector<int> roots = main_scene_roots();
        traverse(roots, [&](int node, const glm::dmat4& world) { add_node(node, world); });
        finish();
        return std::move(scene_);
    }

private:
    // The main scene: the default scene unless it is a "_neural" list, else the first other scene.
    std::vector<int> main_scene_roots() {
        const int count = int(model_.scenes.size());
        if (model_.defaultScene >= count)
            throw Error(strfmt("%s: scene %d does not exist (the file has %d scene%s)", path_.string().c_str(),
                               model_.defaultScene, count, count == 1 ? "" : "s"));
        if (count == 0) {
            // No scenes: glTF leaves it to the application; render every root node (warned).
            std::vector<uint8_t> is_child(model_.nodes.size(), 0);
            for (const tinygltf::Node& n : model_.nodes)
                for (int c : n.children) is_child[size_t(c)] = 1;
            std::vector<int> roots;
            for (size_t i = 0; i < model_.nodes.size(); ++i)
                if (!is_child[i]) roots.push_back(int(i));
            log_warn("%s: no scenes; rendering all %zu root nodes", file_.c_str(), roots.size());
            return roots;
        }
        int chosen = model_.defaultScene;
        if (chosen < 0 || is_neural_scene_name(model_.scenes[size_t(chosen)].name)) {
            chosen = -1;
            for (int i = 0; i < count && chosen < 0; ++i)
                if (!is_neural_scene_name(model_.scenes[size_t(i)].name)) chosen = i;
            if (chosen < 0) chosen = model_.defaultScene >= 0 ? model_.defaultScene : 0;
        }
        scene_index_ = chosen;
        std::vector<int> roots = model_.scenes[size_t(chosen)].nodes;
        for (int r : roots)
            if (r < 0 || size_t(r) >= model_.nodes.size())
                throw Error(strfmt("%s: scene %d lists node %d which does not exist", path_.string().c_str(), chosen, r));
        return roots;
    }

    // Depth-first over the (acyclic, checked) hierarchy in document order; a node reached twice (shared
    // child: invalid glTF) is skipped with a warning so a hostile DAG cannot blow up exponentially.
    template <class Visit>
    void traverse(const std::vector<int>& roots, Visit&& visit) {
        std::vector<uint8_t> seen(model_.nodes.size(), 0);
        std::vector<std::pair<int, glm::dmat4>> stack;
        for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, glm::dmat4(1.0)});
        while (!stack.empty()) {
            const auto [node, parent] = stack.back();
            stack.pop_back();
            if (seen[size_t(node)]++) {
                log_warn("%s: node %d is reached twice (it has two parents); second occurrence skipped", file_.c_str(), node);
                continue;
            }
            glm::dmat4 local;
            if (!local_transform(model_.nodes[size_t(node)], local)) {
                log_warn("%s: node %d ('%s') has a non-finite transform; it and its children are skipped",
                         file_.c_str(), node, model_.nodes[size_t(node)].name.c_str());
                continue;
            }
            const glm::dmat4 world = parent * local;
            visit(node, world);
            const std::vector<int>& children = model_.nodes[size_t(node)].children;
            for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back({*it, world});
        }
    }

    void add_node(int node_index, const glm::dmat4& world) {
        const tinygltf::Node& node = model_.nodes[size_t(node_index)];
        if (node.camera >= 0 && !scene_.has_camera) add_camera(node, world);
        if (auto light = gltf::node_light(model_, node, node_index, world, file_)) scene_.lights.push_back(*light);
        if (node.mesh < 0) return;
        if (size_t(node.mesh) >= model_.meshes.size()) {
            log_warn("%s: node %d refers to mesh %d which does not exist; skipped", file_.c_str(), node_index, node.mesh);
            return;
        }
        Instance inst;
        inst.name = node.name.empty() ? strfmt("node%d", node_index) : node.name;
        // Skinned, or morphed by weights of its own: this node gets its own posed copy of the mesh
        // (gltf_pose.h); a skinned one is in world space, as the node's own transform does not apply.
        gltf::Pose pose;
        if (node.skin >= 0) {
            node_world_transforms();
            const std::string what = strfmt("%s: node %d ('%s')", file_.c_str(), node_index, node.name.c_str());
            if (gltf::skin_joints(model_, node.skin, world_, world_valid_, pose.joints, what)) pose.unskinned = world;
        }
        const bool own_weights = !node.weights.empty() && has_targets(node.mesh);
        int32_t mesh = -1;
        if ((pose.skinned() || own_weights) && posed_copy_fits(node.mesh)) {
            pose.weights = gltf::morph_weights(model_, node_index, node.mesh);
            skinned_instances_ += pose.skinned();
            mesh = add_mesh(build(node.mesh, pose, inst.name), node.mesh);
        } else {
            pose = gltf::Pose{};
            mesh = scene_mesh(node.mesh);
        }
        if (mesh < 0) return;
        inst.mesh = uint32_t(mesh);
        inst.object_to_world = pose.skinned() ? glm::mat4(1.0f) : glm::mat4(world);
        scene_.instances.push_back(std::move(inst));
    }

    // Posed copies are not shared between nodes: their vertices are capped (a hostile file could pose one
    // large mesh on thousands of nodes); past the cap nodes share the unposed mesh, warned once.
    bool posed_copy_fits(int m) {
        uint64_t vertices = 0;
        for (size_t p = 0; p < model_.meshes[size_t(m)].primitives.size(); ++p) {
            const auto& attributes = model_.meshes[size_t(m)].primitives[p].attributes;
            auto a = attributes.find("POSITION");
            if (a != attributes.end())
                vertices += gltf::accessor_count(model_, a->second, strfmt("%s: mesh %d primitive %zu POSITION",
                                                                            file_.c_str(), m, p));
        }
        if (posed_vertices_ + vertices <= MAX_POSED_VERTICES) {
            posed_vertices_ += vertices;
            return true;
        }
        if (!posed_cap_warned_)
            log_warn("%s: skinned/morphed copies exceed %llu vertices; further nodes show their mesh unposed",
                     file_.c_str(), (unsigned long long)MAX_POSED_VERTICES);
        posed_cap_warned_ = true;
        return false;
    }

    bool has_targets(int m) const {
        for (const tinygltf::Primitive& p : model_.meshes[size_t(m)].primitives)
            if (!p.targets.empty()) return true;
        return false;
    }

    // World transform of every node through its parent chain, whatever scene it is in (skin joints need
    // not be under the skinned node). The graph is acyclic (check_node_graph); a second parent is ignored
    // as in traverse(). world_valid_[n] = 0 where a transform on the chain is not finite.
    void node_world_transforms() {
        const size_t n = model_.nodes.size();
        if (world_.size() == n) return;
        std::vector<int> parent(n, -1);
        for (size_t i = 0; i < n; ++i)
            for (int c : model_.nodes[i].children)
                if (parent[size_t(c)] < 0) parent[size_t(c)] = int(i);
        world_.assign(n, glm::dmat4(1.0));
        world_valid_.assign(n, 0);
        std::vector<uint8_t> done(n, 0);
        std::vector<size_t> chain;
        for (size_t i = 0; i < n; ++i) {
            chain.clear();
            for (size_t k = i; !done[k]; k = size_t(parent[k])) {
                chain.push_back(k);
                if (parent[k] < 0) break;
            }
            for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
                const size_t k = *it;
                const int p = parent[k];
                glm::dmat4 local;
                world_valid_[k] = local_transform(model_.nodes[k], local) && (p < 0 || world_valid_[size_t(p)]);
                if (world_valid_[k]) world_[k] = p < 0 ? local : world_[size_t(p)] * local;
                done[k] = 1;
            }
        }
    }

    void add_camera(const tinygltf::Node& node, const glm::dmat4& world) {
        if (size_t(node.camera) >= model_.cameras.size()) return;
        const tinygltf::Camera& cam = model_.cameras[size_t(node.camera)];
        if (cam.type != "perspective") {
            log_warn("%s: camera '%s' is %s; only perspective cameras are used", file_.c_str(), cam.name.c_str(),
                     cam.type.c_str());
            return;
        }
        const double yfov = cam.perspective.yfov;
        // glTF cameras look down -z with +y up, in the node's frame (scale removed by normalising).
        const glm::dvec3 eye(world[3]);
        const glm::dvec3 forward = -glm::dvec3(world[2]), up = glm::dvec3(world[1]);
        const double fl = glm::length(forward), ul = glm::length(up);
        if (!(yfov > 1e-4 && yfov < 3.1) || !(fl > 0.0) || !(ul > 0.0) || !std::isfinite(fl) || !std::isfinite(ul)) {
            log_warn("%s: camera '%s' has an invalid fov or transform; ignored", file_.c_str(), cam.name.c_str());
            return;
        }
        scene_.camera.eye = glm::vec3(eye);
        scene_.camera.target = glm::vec3(eye + forward / fl);
        scene_.camera.up = glm::vec3(up / ul);
        scene_.camera.yfov = float(yfov);
        scene_.has_camera = true;
    }

    // Index of glTF mesh `m` in scene_.meshes, building it on first use; -1 when it has no triangles.
    int32_t scene_mesh(int m) {
        auto it = mesh_map_.find(m);
        if (it != mesh_map_.end()) return it->second;
        // Shared by every node without a pose of its own: morph targets at the mesh's default weights.
        gltf::Pose pose;
        if (has_targets(m)) pose.weights = gltf::morph_weights(model_, -1, m);
        const int32_t slot = add_mesh(build(m, pose), m);
        mesh_map_[m] = slot;
        return slot;
    }

    // Keeps a mesh with triangles (returns its Scene::meshes index, else -1).
    int32_t add_mesh(Mesh mesh, int gltf_mesh) {
        if (mesh.triangle_count() == 0) return -1;
        scene_.meshes.push_back(std::move(mesh));
        gltf_mesh_of_.push_back(gltf_mesh);
        return int32_t(scene_.meshes.size() - 1);
    }

    // glTF mesh `m` as one Mesh, posed by `pose`; a node's own posed copy is named "mesh@node".
    Mesh build(int m, const gltf::Pose& pose, const std::string& node_name = "") {
        const tinygltf::Mesh& src = model_.meshes[size_t(m)];
        std::string name = src.name.empty() ? strfmt("mesh%d", m) : src.name;
        if (!node_name.empty()) name += "@" + node_name;
        morphed_meshes_ += pose.morphed() && has_targets(m);
        std::vector<PrimitiveData> prims;
        std::map<std::string, int> skipped_modes;
        for (size_t p = 0; p < src.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = src.primitives[p];
            const std::string what = strfmt("%s: mesh %d ('%s') primitive %zu", file_.c_str(), m, src.name.c_str(), p);
            const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
            if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                mode != TINYGLTF_MODE_TRIANGLE_FAN) {
                ++skipped_modes[mode_name(mode)];
                continue;
            }
            auto attr = [&](const char* key) {
                auto a = prim.attributes.find(key);
                return a == prim.attributes.end() ? -1 : a->second;
            };
            if (attr("POSITION") < 0) {
                log_warn("%s has no POSITION; skipped", what.c_str());
                continue;
            }
            PrimitiveData d;
            d.positions = to_vectors<3, glm::vec3>(gltf::read_floats(model_, attr("POSITION"), 3, what + " POSITION"));
            const size_t nv = d.positions.size();
            auto optional = [&](const char* key, int comps, auto& dst) {
                using V = typename std::decay_t<decltype(dst)>::value_type;
                if (attr(key) < 0) return;
                std::vector<V> v = to_vectors<V::length(), V>(gltf::read_floats(model_, attr(key), comps, what + " " + key));
                if (v.size() != nv) log_warn("%s %s has %zu elements for %zu vertices; ignored", what.c_str(), key, v.size(), nv);
                else dst = std::move(v);
            };
            optional("NORMAL", 3, d.normals);
            optional("TEXCOORD_0", 2, d.uv0);
            optional("TEXCOORD_1", 2, d.uv1);
            d.material = default_material_;
            if (prim.material >= 0 && uint32_t(prim.material) < default_material_) d.material = uint32_t(prim.material);
            else if (prim.material >= 0) log_warn("%s: material %d does not exist; default used", what.c_str(), prim.material);
            const Material& mat = scene_.materials[d.material];
            d.needs_tangents = mat.normal_tex.texture >= 0;
            d.normal_map_uv_set = mat.normal_tex.uv_set;
            if (d.needs_tangents) optional("TANGENT", 4, d.tangents);
            if (pose.morphed() || pose.skinned()) gltf::apply_pose(model_, prim, pose, d, what);
            if (prim.indices >= 0) {
                d.indices = gltf::read_indices(model_, prim.indices, what + " indices");
            } else {
                d.indices.resize(nv);
                std::iota(d.indices.begin(), d.indices.end(), 0u);
            }
            if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) d.indices = strip_to_list(d.indices);
            else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) d.indices = fan_to_list(d.indices);
            else if (d.indices.size() % 3 != 0) {
                log_warn("%s: %zu indices is not a multiple of 3; the incomplete last triangle is dropped",
                         what.c_str(), d.indices.size());
                d.indices.resize(d.indices.size() - d.indices.size() % 3);
            }
            prims.push_back(std::move(d));
        }
        for (const auto& [mode, n] : skipped_modes)
            log_warn("%s: mesh %d ('%s'): skipped %d primitive%s of mode %s (only triangles are rendered)",
                     file_.c_str(), m, src.name.c_str(), n, n == 1 ? "" : "s", mode.c_str());
        MeshBuildReport r;
        Mesh mesh = build_mesh(name, prims, r);
        const char* mn = name.c_str();
        if (r.dropped_huge)
            throw Error(strfmt("%s: coordinates out of range: %llu triangles of mesh '%s' have |coordinate| > %g",
                               path_.string().c_str(), (unsigned long long)r.dropped_huge, mn, double(MAX_COORDINATE)));
        if (r.dropped_non_finite)
            log_warn("%s: mesh '%s': dropped %llu triangles with non-finite (NaN/Inf) positions", file_.c_str(), mn,
                     (unsigned long long)r.dropped_non_finite);
        if (r.dropped_out_of_range_index)
            log_warn("%s: mesh '%s': dropped %llu triangles with out-of-range vertex indices", file_.c_str(), mn,
                     (unsigned long long)r.dropped_out_of_range_index);
        if (r.all_zero_area)
            log_warn("%s: mesh '%s': every triangle has zero area; mesh skipped", file_.c_str(), mn);
        if (r.repaired_normals)
            log_warn("%s: mesh '%s': repaired %llu zero, non-finite or non-unit normals", file_.c_str(), mn,
                     (unsigned long long)r.repaired_normals);
        if (r.zero_area_triangles && !r.all_zero_area)
            log_debug("%s: mesh '%s': %llu zero-area triangles kept", file_.c_str(), mn, (unsigned long long)r.zero_area_triangles);
        if (r.generated_tangents)
            log_debug("%s: mesh '%s': generated %llu tangents (%llu without UV information)", file_.c_str(), mn,
                      (unsigned long long)r.generated_tangents, (unsigned long long)r.degenerate_uv_tangents);
        return mesh;
    }

    void finish() {
        // Node transforms can push finite object-space data out of range (a 1e30 scale).
        const Aabb b = scene_.world_bounds();
        if (!b.empty()) {
            for (int a = 0; a < 3; ++a)
                if (!std::isfinite(b.lo[a]) || !std::isfinite(b.hi[a]) || std::fabs(b.lo[a]) > MAX_WORLD_COORDINATE ||
                    std::fabs(b.hi[a]) > MAX_WORLD_COORDINATE)
                    throw Error(strfmt("%s: coordinates out of range: world bounds reach beyond %g after node transforms",
                                       path_.string().c_str(), double(MAX_WORLD_COORDINATE)));
        }
        subdivide_scene(scene_, options_.subdivide);
        const SceneStats stats = scene_stats(scene_);
        if (stats.instanced_triangles == 0) {
            if (options_.require_geometry)
                throw Error(strfmt("%s: no renderable geometry (no finite triangle with non-zero area in the scene)",
                                   path_.string().c_str()));
            log_warn("%s: no renderable geometry", file_.c_str());
        }
        std::string how;
        if (!options_.neural_glob.empty()) {
            how = mark_neural_by_glob(scene_, options_.neural_glob);
        } else {
            how = mark_neural_by_scene();
        }
        log_info("%s; neural: %s", describe(scene_).c_str(), how.c_str());
        if (!scene_.lights.empty()) {
            uint32_t count[3] = {0, 0, 0};
            for (const PunctualLight& l : scene_.lights) ++count[uint32_t(l.type)];
            log_info("%s: %zu punctual light%s (%u point, %u spot, %u directional)", file_.c_str(), scene_.lights.size(),
                     scene_.lights.size() == 1 ? "" : "s", count[0], count[1], count[2]);
        }
        if (skinned_instances_ || morphed_meshes_)
            log_info("%s: %u skinned instance%s posed by the joints' node transforms, %u mesh%s morphed at the default "
                     "weights (no animation is played)", file_.c_str(), skinned_instances_,
                     skinned_instances_ == 1 ? "" : "s", morphed_meshes_, morphed_meshes_ == 1 ? "" : "es");
    }

    // ARCHITECTURE.md "Which assets are neural": nodes of a "*_neural" scene are neural. That scene holds its
    // own copies of the nodes, so main-scene instances are matched by (node name, glTF mesh).
    std::string mark_neural_by_scene() {
        std::string used;
        std::set<std::pair<std::string, int>> keys;
        for (size_t s = 0; s < model_.scenes.size(); ++s) {
            if (int(s) == scene_index_ || !is_neural_scene_name(model_.scenes[s].name)) continue;
            used += (used.empty() ? "scene '" : ", '") + model_.scenes[s].name + "'";
            bool bad = false;
            for (int r : model_.scenes[s].nodes) bad |= r < 0 || size_t(r) >= model_.nodes.size();
            if (bad) {
                log_warn("%s: scene '%s' lists a node that does not exist; ignored", file_.c_str(), model_.scenes[s].name.c_str());
                continue;
            }
            traverse(model_.scenes[s].nodes, [&](int node, const glm::dmat4&) {
                const tinygltf::Node& n = model_.nodes[size_t(node)];
                if (n.mesh >= 0) keys.insert({n.name.empty() ? strfmt("node%d", node) : n.name, n.mesh});
            });
        }
        if (used.empty()) return "none";
        for (Instance& inst : scene_.instances)
            inst.neural = keys.count({inst.name, gltf_mesh_of_[inst.mesh]}) > 0;
        return used;
    }

    std::filesystem::path path_;
    std::string file_;
    SceneLoadOptions options_;
    tinygltf::Model model_;
    Scene scene_;
    uint32_t default_material_ = 0;
    int scene_index_ = -1;
    std::map<int, int32_t> mesh_map_; // glTF mesh -> Scene::meshes index (-1: no triangles), unposed nodes
    std::vector<int> gltf_mesh_of_;   // Scene::meshes index -> glTF mesh
    std::vector<glm::dmat4> world_;   // node_world_transforms()
    std::vector<uint8_t> world_valid_;
    uint32_t skinned_instances_ = 0, morphed_meshes_ = 0;
    uint64_t posed_vertices_ = 0; // in posed copies (posed_copy_fits)
    bool posed_cap_warned_ = false;
};

} // namespace

std::string mark_neural_by_glob(Scene& scene, const std::string& glob) {
    for (Instance& inst : scene.instances) inst.neural = glob_match(glob, inst.name);
    return "glob '" + glob + "'";
}

Scene load_gltf(const std::filesystem::path& path, const SceneLoadOptions& options) {
    return Loader(path, options).load();
}

} // namespace nbvh
