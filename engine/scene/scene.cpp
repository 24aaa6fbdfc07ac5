#include "engine/scene/scene.h"

#include <glm/gtc/matrix_access.hpp>

namespace nbvh {

Aabb Mesh::bounds() const {
    Aabb b;
    for (const glm::vec3& p : positions) b.grow(p);
    return b;
}

Aabb Scene::world_bounds() const {
    Aabb b;
    for (const Instance& inst : instances) {
        const Aabb local = meshes[inst.mesh].bounds();
        if (local.empty()) continue;
        for (int corner = 0; corner < 8; ++corner) {
            const glm::vec3 p((corner & 1) ? local.hi.x : local.lo.x, (corner & 2) ? local.hi.y : local.lo.y,
                              (corner & 4) ? local.hi.z : local.lo.z);
            b.grow(glm::vec3(inst.object_to_world * glm::vec4(p, 1.0f)));
        }
    }
    return b;
}

} // namespace nbvh
