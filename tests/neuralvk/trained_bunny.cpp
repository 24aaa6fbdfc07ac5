#include "tests/neuralvk/trained_bunny.h"

#include "engine/scene/gltf_loader.h"
#include "tests/support/test_support.h"
#include "trainer/model_export.h"
#include "trainer/trainer.h"

namespace nbvh::test {

const TrainedBunny& trained_bunny() {
    // Built in place (never moved): the asset keeps a pointer to the scene.
    static const TrainedBunny* bunny = [] {
        auto* x = new TrainedBunny;
        SceneLoadOptions lo;
        lo.neural_glob = "*";
        x->scene = load_gltf(scenes_dir() / "stanford_bunny" / "stanford_bunny.glb", lo);
        x->asset = make_training_asset(x->scene, pick_neural_mesh(x->scene));
        TrainOptions opt = default_train_options(BackendChoice::cpu);
        opt.steps = 300;
        opt.batch_size = 2048;
        opt.target_nodes = 200;
        opt.network.log2_hash_size = 14;
        opt.lods = 2;
        opt.threads = 2;
        auto backend = make_backend(BackendChoice::cpu, x->asset, opt);
        const TrainResult r = train_asset(x->asset, opt, *backend);
        x->model = make_neural_model(x->asset, r, opt, "stanford_bunny", 0);
        x->check = evaluate_network(x->asset, cut_of_tree(x->asset, r.tree, 0), r.weights, 2000, 11);
        return x;
    }();
    return *bunny;
}

} // namespace nbvh::test
