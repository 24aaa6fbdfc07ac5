#include "tests/fuzz/fuzz_targets.h"

#include <cmath>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "engine/core/error.h"
#include "engine/neural/model_file.h"
#include "engine/scene/gltf_loader.h"
#include "tests/model/tiny_model.h"

namespace nbvh::fuzz {
namespace {

// An nbvh::Error must be one non-empty line (it is printed as "nbvh: error: <what>").
void check_error_line(const Error& e) {
    const std::string what = e.what();
    NBVH_CHECK_MSG(!what.empty() && what.find('\n') == std::string::npos && what.find('\r') == std::string::npos,
                   ("nbvh::Error is not one line: " + what).c_str());
}

// ---- model ----

// What the renderer does with a loaded model, minus the GPU, and the writer's round trip.
void check_model(const NeuralModel& m) {
    const NbvhTree tree = m.tree();
    for (uint32_t l = 0; l < m.lod_count; ++l)
        for (const ModelAsset& a : m.assets) (void)tree.to_gpu_layout(l, a.root);
    (void)model_gpu_bytes(m);
    try {
        const std::vector<uint8_t> again = serialize_model(m);
        NBVH_CHECK_MSG(serialize_model(parse_model(again, "round trip")) == again,
                       "a loaded model does not survive serialise / parse unchanged");
    } catch (const Error& e) {
        fail_invariant(__FILE__, __LINE__, "a loaded model serialises and re-loads", e.what());
    }
}

Outcome parse_and_check(std::span<const uint8_t> bytes) {
    NeuralModel m;
    try {
        m = parse_model(bytes, "fuzz");
    } catch (const Error& e) {
        check_error_line(e);
        return Outcome::rejected;
    }
    check_model(m);
    return Outcome::loaded;
}

// ---- glTF ----

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// gltf_loader.h and scene.h promise: finite positions and unit normals, indices and materials in range,
// attributes per vertex, textures of width * height texels, a default material.
void check_scene(const Scene& s) {
    NBVH_CHECK(!s.materials.empty());
    for (const Texture& t : s.textures)
        NBVH_CHECK(t.width > 0 && t.height > 0 && t.rgba8.size() == size_t(t.width) * t.height * 4);
    for (const Material& m : s.materials)
        for (const TextureRef* r : {&m.base_color_tex, &m.metallic_roughness_tex, &m.normal_tex, &m.emissive_tex})
            NBVH_CHECK(r->texture >= -1 && r->texture < int32_t(s.textures.size()) && r->uv_set <= 1);
    for (const Mesh& mesh : s.meshes) {
        const size_t nv = mesh.positions.size();
        NBVH_CHECK(mesh.indices.size() % 3 == 0 && mesh.triangle_material.size() == mesh.triangle_count());
        NBVH_CHECK(mesh.normals.size() == nv);
        NBVH_CHECK(mesh.uv0.empty() || mesh.uv0.size() == nv);
        NBVH_CHECK(mesh.uv1.empty() || mesh.uv1.size() == nv);
        NBVH_CHECK(mesh.tangents.empty() || mesh.tangents.size() == nv);
        for (uint32_t i : mesh.indices) NBVH_CHECK(i < nv);
        for (uint32_t m : mesh.triangle_material) NBVH_CHECK(m < s.materials.size());
        for (const glm::vec3& p : mesh.positions) NBVH_CHECK(finite(p));
        for (const glm::vec3& n : mesh.normals) NBVH_CHECK(finite(n) && std::fabs(glm::length(n) - 1.0f) < 1e-3f);
    }
    for (const Instance& inst : s.instances) {
        NBVH_CHECK(inst.mesh < s.meshes.size());
        for (int c = 0; c < 4; ++c) NBVH_CHECK(finite(glm::vec3(inst.object_to_world[c])));
    }
    const Aabb b = s.world_bounds();
    NBVH_CHECK(b.empty() || (finite(b.lo) && finite(b.hi)));
    // gltf_lights.h: finite placement, unit direction, non-negative finite colour, intensity and range,
    // ordered cone angles.
    for (const PunctualLight& l : s.lights) {
        NBVH_CHECK(finite(l.position) && finite(l.direction) && std::fabs(glm::length(l.direction) - 1.0f) < 1e-3f);
        NBVH_CHECK(finite(l.color) && l.color.x >= 0.0f && l.color.y >= 0.0f && l.color.z >= 0.0f);
        NBVH_CHECK(std::isfinite(l.intensity) && l.intensity >= 0.0f && std::isfinite(l.range) && l.range >= 0.0f);
        NBVH_CHECK(l.type != LightType::spot || (l.inner_cone >= 0.0f && l.inner_cone < l.outer_cone &&
                                                 l.outer_cone <= 1.5708f));
    }
}

// A directory of this process for the input file, removed at exit.
struct TempDir {
    std::filesystem::path path;
    TempDir() {
        path = std::filesystem::temp_directory_path() / ("nbvh-fuzz-gltf-" + std::to_string(::getpid()));
        std::filesystem::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
};

} // namespace

Outcome model_input(std::span<const uint8_t> bytes) {
    const Outcome as_given = parse_and_check(bytes);
    if (bytes.size() >= model_io::HEADER_BYTES && std::memcmp(bytes.data(), model_io::MAGIC, 4) == 0) {
        std::vector<uint8_t> fixed(bytes.begin(), bytes.end());
        test::refresh_checksums(fixed);
        if (!std::equal(fixed.begin(), fixed.end(), bytes.begin())) (void)parse_and_check(fixed);
    }
    try {
        const std::vector<NbvhNode> nodes = import_official_tree(bytes, "fuzz");
        (void)NbvhTree::from_nodes(nodes, 1).to_gpu_layout(0);
    } catch (const Error& e) {
        check_error_line(e);
    }
    return as_given;
}

Outcome gltf_file(const std::filesystem::path& path) {
    Scene scene;
    try {
        scene = load_gltf(path);
    } catch (const Error& e) {
        check_error_line(e);
        return Outcome::rejected;
    }
    check_scene(scene);
    return Outcome::loaded;
}

Outcome gltf_input(std::span<const uint8_t> bytes) {
    static const TempDir dir;
    const bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    const std::filesystem::path file = dir.path / (glb ? "in.glb" : "in.gltf");
    std::error_code ec;
    std::filesystem::remove(dir.path / (glb ? "in.gltf" : "in.glb"), ec); // no stale file for a URI to find
    {
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        NBVH_CHECK_MSG(out.good(), file.c_str());
    }
    return gltf_file(file);
}

} // namespace nbvh::fuzz
