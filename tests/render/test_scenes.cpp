#include "tests/render/test_scenes.h"

namespace nbvh::test {

Scene make_quad_scene() {
    Scene s;
    Mesh m;
    m.name = "quad";
    m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    m.normals.assign(4, glm::vec3(0, 0, 1));
    m.uv0 = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.triangle_material = {0, 0};
    s.meshes.push_back(m);
    Material mat;
    mat.base_color = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    mat.metallic = 0.0f;
    mat.roughness = 0.5f;
    s.materials.push_back(mat);
    Instance inst;
    inst.name = "quad";
    inst.mesh = 0;
    s.instances.push_back(inst);
    s.camera.eye = {0, 0, 3};
    s.camera.target = {0, 0, 0};
    s.has_camera = true;
    return s;
}

} // namespace nbvh::test
