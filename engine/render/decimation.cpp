#include "engine/render/decimation.h"

#include <algorithm>
#include <cmath>

#include "engine/render/gpu_memory.h"
#include "engine/scene/simplify.h"

namespace nbvh::render {

Decimation decimate_to_budget(const Scene& scene, std::span<const uint32_t> meshes, uint64_t budget_bytes,
                              double tolerance) {
    Decimation d;
    d.budget_bytes = budget_bytes;
    d.scene = scene;
    for (uint32_t m : meshes) {
        d.source_triangles += scene.meshes[m].triangle_count();
        d.source_bytes += mesh_gpu_bytes(scene.meshes[m]);
    }
    d.bytes = d.source_bytes;
    d.triangles = d.source_triangles;
    if (d.source_bytes <= budget_bytes || d.source_triangles == 0) {
        d.fits_unsimplified = true;
        return d;
    }
    // Bytes are about proportional to triangles (vertices ~ triangles / 2, BLAS nodes ~ triangles / 2 for
    // leaves of up to 2-4): start from the source's bytes per triangle, then rescale by the miss.
    double ratio = double(budget_bytes) / double(d.source_bytes);
    double best_miss = INFINITY;
    for (uint32_t it = 0; it < 12; ++it) {
        Scene s = scene;
        uint64_t bytes = 0, tris = 0;
        bool sloppy = false;
        for (uint32_t m : meshes) {
            const Mesh& src = scene.meshes[m];
            const uint32_t target =
                uint32_t(std::clamp(double(src.triangle_count()) * ratio, 1.0, double(src.triangle_count())));
            SimplifyStats st;
            s.meshes[m] = simplify_mesh(src, target, &st);
            sloppy = sloppy || st.sloppy;
            bytes += mesh_gpu_bytes(s.meshes[m]);
            tris += s.meshes[m].triangle_count();
        }
        d.iterations = it + 1;
        const double miss = std::fabs(double(bytes) / double(budget_bytes) - 1.0);
        if (miss < best_miss) {
            best_miss = miss;
            d.scene = std::move(s);
            d.bytes = bytes;
            d.triangles = tris;
            d.sloppy = sloppy;
        }
        if (miss <= tolerance || bytes == 0) break;
        const double next = ratio * double(budget_bytes) / double(bytes);
        if (next >= 1.0 && ratio >= 1.0) break;
        ratio = std::min(next, 1.0);
    }
    return d;
}

} // namespace nbvh::render
