// Small procedural meshes for the built-in scene (object space, metres, +y up, CCW outward faces).
// Every generator returns a complete nbvh::Mesh: positions, unit normals, uv0, indices and one
// material per triangle.
#pragma once
#include <cstdint>
#include <string>

#include "engine/scene/scene.h"

namespace nbvh::assets {

// UV sphere: `segments` around y, `rings` from pole to pole. Analytic normals.
Mesh make_sphere(const std::string& name, float radius, uint32_t segments, uint32_t rings, uint32_t material);

// Axis-aligned box centred at the origin with flat faces (24 vertices, 12 triangles).
Mesh make_box(const std::string& name, const glm::vec3& half_extent, uint32_t material);

// Square in the xz plane at y = 0 facing +y, side `size`, uv0 spanning [0,1]².
Mesh make_ground(const std::string& name, float size, uint32_t material);

// Closed vertical cylinder (side, top and bottom caps), centred at the origin.
Mesh make_cylinder(const std::string& name, float radius, float half_height, uint32_t segments, uint32_t material);

// Area-weighted smooth vertex normals from the triangles (unit, finite; a vertex with no area gets +y).
void compute_smooth_normals(Mesh& mesh);

} // namespace nbvh::assets
