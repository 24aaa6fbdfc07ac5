// Environment lighting: an equirectangular map (.hdr / .exr, linear RGB) or our procedural default sky.
// Mapping (shared with the renderer): direction d (world, +y up) -> u = 0.5 + atan2(d.x, -d.z) / (2 pi),
// v = acos(clamp(d.y, -1, 1)) / pi; row 0 of the image is the zenith (v = 0). Environment::rotation turns
// the map about +y (radians).
#pragma once
#include <filesystem>

#include "engine/scene/scene.h"

namespace nbvh {

// Largest accepted environment map edge (texels); bigger files are refused before their pixels are used.
constexpr uint32_t MAX_ENVIRONMENT_EDGE = 16384;

// Loads an equirectangular map. Non-finite texels become 0 and negative components 0 (a warning with the
// count), so importance sampling never sees NaN/Inf. Throws nbvh::Error for unreadable files, unsupported
// extensions or sizes beyond MAX_ENVIRONMENT_EDGE. Non-2:1 maps load with a warning.
Environment load_environment(const std::filesystem::path& path);

// A procedural clear sky (horizon-to-zenith gradient, darker ground, soft sun lobe) as a 256x128 map, so
// the default environment goes through the same sampling code as a loaded one.
Environment default_sky();

// Constant radiance in every direction (Environment::rgb empty).
Environment constant_environment(const glm::vec3& radiance);

} // namespace nbvh
