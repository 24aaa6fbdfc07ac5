// Turns the triangle primitives of one glTF mesh into one nbvh::Mesh: drops invalid triangles, compacts the
// vertices to those referenced, merges primitives (per-triangle material), fixes or generates normals and
// generates tangents where a normal map needs them. Format-agnostic (no tinygltf here), so tests can feed it
// hand-made data.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "engine/scene/scene.h"

namespace nbvh {

// Largest accepted |coordinate| in object space (metres). Beyond ~1e9 the float32 cross products used for
// normals and ray-triangle tests overflow (|e1 x e2|^2 ~ |x|^4); 1e8 keeps margin for instance transforms.
constexpr float MAX_COORDINATE = 1e8f;

// One triangle primitive, already decoded. `indices` is a triangle list (strips/fans converted); it may
// still hold out-of-range indices and reference non-finite positions: build_mesh() filters them.
struct PrimitiveData {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;  // empty, or one per position (possibly zero / non-unit / NaN)
    std::vector<glm::vec4> tangents; // empty, or one per position
    std::vector<glm::vec2> uv0, uv1; // empty, or one per position
    std::vector<uint32_t> indices;
    uint32_t material = 0;
    uint32_t normal_map_uv_set = 0; // UV set of the material's normal map (tangent generation)
    bool needs_tangents = false;    // the material has a normal map
};

// What build_mesh() dropped or repaired (the loader turns non-zero counts into warnings).
struct MeshBuildReport {
    uint64_t dropped_out_of_range_index = 0;
    uint64_t dropped_non_finite = 0;
    uint64_t dropped_huge = 0;           // |coordinate| > MAX_COORDINATE
    uint64_t zero_area_triangles = 0;    // kept (never hit), reported
    uint64_t repaired_normals = 0;       // given normals that were zero / non-finite (replaced) or non-unit
    uint64_t generated_normals = 0;      // vertices whose normal was generated (attribute absent)
    uint64_t generated_tangents = 0;
    uint64_t degenerate_uv_tangents = 0; // tangents that fell back to an arbitrary frame around the normal
    bool all_zero_area = false;          // mesh had triangles but none with area: its triangles were removed
};

Mesh build_mesh(const std::string& name, std::vector<PrimitiveData>& primitives, MeshBuildReport& report);

// Converts TRIANGLE_STRIP (mode 5) / TRIANGLE_FAN (mode 6) index sequences into a triangle list (glTF 2.0
// §3.7.2.1 winding: strips alternate). Trailing incomplete triangles of a list are cut by the caller.
std::vector<uint32_t> strip_to_list(const std::vector<uint32_t>& strip);
std::vector<uint32_t> fan_to_list(const std::vector<uint32_t>& fan);

// An arbitrary unit tangent perpendicular to unit `n` (Duff et al. 2017, branchless ONB).
glm::vec3 any_perpendicular(const glm::vec3& n);

} // namespace nbvh
