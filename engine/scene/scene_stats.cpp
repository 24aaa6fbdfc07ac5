#include "engine/scene/scene_stats.h"

#include <filesystem>

#include "engine/core/log.h"

namespace nbvh {

SceneStats scene_stats(const Scene& scene) {
    SceneStats s;
    s.meshes = scene.meshes.size();
    s.instances = scene.instances.size();
    s.materials = scene.materials.size();
    s.textures = scene.textures.size();
    for (const Mesh& m : scene.meshes) s.triangles += m.triangle_count();
    for (const Instance& inst : scene.instances) {
        const uint64_t t = inst.mesh < scene.meshes.size() ? scene.meshes[inst.mesh].triangle_count() : 0;
        s.instanced_triangles += t;
        if (inst.neural) {
            ++s.neural_instances;
            s.neural_triangles += t;
        }
    }
    return s;
}

std::string describe(const Scene& scene) {
    const SceneStats s = scene_stats(scene);
    const Environment& env = scene.environment;
    const std::string env_text = !env.rgb.empty() ? strfmt("%ux%u", env.width, env.height)
                                 : env.empty()    ? std::string("none")
                                                  : std::string("constant");
    return strfmt("%s: %llu meshes, %llu instances (%llu neural), %llu triangles (%llu instanced), %llu materials, "
                  "%llu textures, camera: %s, environment: %s",
                  std::filesystem::path(scene.source).filename().string().c_str(), (unsigned long long)s.meshes,
                  (unsigned long long)s.instances, (unsigned long long)s.neural_instances,
                  (unsigned long long)s.triangles, (unsigned long long)s.instanced_triangles,
                  (unsigned long long)s.materials, (unsigned long long)s.textures,
                  scene.has_camera ? "glTF" : "automatic", env_text.c_str());
}

bool glob_match(const std::string& pattern, const std::string& name) {
    size_t p = 0, n = 0, star = std::string::npos, resume = 0;
    while (n < name.size()) {
        if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == name[n])) {
            ++p;
            ++n;
        } else if (p < pattern.size() && pattern[p] == '*') {
            star = p++;
            resume = n;
        } else if (star != std::string::npos) {
            p = star + 1;
            n = ++resume;
        } else {
            return false;
        }
    }
    while (p < pattern.size() && pattern[p] == '*') ++p;
    return p == pattern.size();
}

} // namespace nbvh
