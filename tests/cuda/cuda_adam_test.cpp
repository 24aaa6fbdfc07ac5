// The CUDA trainer's Adam (k_adam: four parameters per thread, both parameter groups in one launch, the
// bias-correction factors from a table) against the CPU trainer's neural::Adam fed the gradients the
// step read back: after every step, every fp32 master weight within rounding of the host's, and every
// fp16 copy the kernels read equal to its master rounded to nearest. Covers the sparse skip of zero grid
// gradients (entries trained in one step and not the next keep their moments and step counters, so the
// counters diverge across steps), the fast mode's fp16 fine-level gradients and the deterministic mode's
// fp32 ones. Skip without a GPU.
#include <cmath>

#include <gtest/gtest.h>

#include "engine/neural/adam.h"
#include "engine/neural/fp16.h"
#include "tests/cuda/cuda_test_support.h"
#include "tests/trainer/trainer_test_scenes.h"
#include "trainer/cuda/cuda_backend.h"

namespace nbvh {
namespace {

// Parameters whose GPU and host updates differ by more than rounding: the bias factors come from the
// device's and the host's powf, and the compilers may contract the update's products differently (the
// gradient's scale, g x (1 / scale / samples) on the GPU and g x 1 / (scale x samples) on the host, gives
// the same bits for a power-of-two loss scale). A missed or doubled update, a wrong step counter or bias
// factor moves a weight by 1e-3 to 1e-2 (~learning rate), orders above the bound.
size_t count_mismatches(const std::vector<float>& gpu, const std::vector<float>& host, float lr,
                        const char* what) {
    size_t bad = 0;
    for (size_t i = 0; i < gpu.size(); ++i) {
        const float tol = 1e-5f * lr + 1e-6f * std::fabs(host[i]);
        if (!(std::fabs(gpu[i] - host[i]) <= tol)) {
            if (bad < 5) ADD_FAILURE() << what << " " << i << ": gpu " << gpu[i] << " host " << host[i];
            ++bad;
        }
    }
    return bad;
}

void expect_adam_matches_host(bool deterministic) {
    const test::MeshAsset m(test::height_field(32, 0.2f, 1.0f, glm::vec3(0.0f)));
    TrainingCut cut = test::cut_at_depth(m.asset, 5);
    CudaBackendOptions opt;
    opt.deterministic = deterministic;
    neural::AdamConfig adam; // tcnn's defaults (lr 1e-2), skip of zero grid gradients on
    auto gpu = make_cuda_backend_ex(m.asset, NeuralConfig{.log2_hash_size = 12}, adam, opt, 3);
    neural::NetworkWeights host;
    gpu->read_weights(host);
    neural::AdamConfig host_cfg = adam;
    host_cfg.loss_scale = 1.0f; // read_last_step's gradients have the loss scale removed
    neural::Adam host_adam(host_cfg, host.mlp.size(), host.grid.size());
    // Grid values with a zero gradient in a step after one that trained them: there the skip keeps non-zero
    // moments and a step counter that falls behind.
    std::vector<bool> trained(host.grid.size(), false);
    size_t skipped_after_training = 0;
    for (uint32_t s = 0; s < 4; ++s) {
        SCOPED_TRACE("step " + std::to_string(s));
        // 2,000 rays: some grid entries trained in one step are untouched in the next.
        const StepStats st = gpu->step(test::fixed_cut_step(s, 2000, 11, cut));
        ASSERT_FALSE(st.skipped) << st.skip_reason;
        std::vector<CudaDebugSample> samples;
        std::vector<float> mg, gg;
        gpu->read_last_step(samples, mg, gg);
        for (size_t i = 0; i < gg.size(); ++i) {
            skipped_after_training += gg[i] == 0.0f && trained[i] ? 1u : 0u;
            trained[i] = trained[i] || gg[i] != 0.0f;
        }
        const float lr = neural::lr_at_step(adam, s);
        host_adam.step(host, mg, gg);
        neural::NetworkWeights w;
        gpu->read_weights(w);
        ASSERT_EQ(w.mlp.size(), host.mlp.size());
        ASSERT_EQ(w.grid.size(), host.grid.size());
        EXPECT_EQ(count_mismatches(w.mlp, host.mlp, lr, "mlp"), 0u);
        EXPECT_EQ(count_mismatches(w.grid, host.grid, lr, "grid"), 0u);
        std::vector<uint16_t> mh, gh;
        gpu->read_half_weights(mh, gh);
        ASSERT_EQ(mh.size(), w.mlp.size());
        ASSERT_EQ(gh.size(), w.grid.size());
        size_t stale = 0;
        for (size_t i = 0; i < mh.size(); ++i) stale += mh[i] != float_to_half_bits(w.mlp[i]) ? 1u : 0u;
        for (size_t i = 0; i < gh.size(); ++i) stale += gh[i] != float_to_half_bits(w.grid[i]) ? 1u : 0u;
        EXPECT_EQ(stale, 0u) << "fp16 copies not equal to their fp32 masters rounded to nearest";
    }
    EXPECT_GT(skipped_after_training, 0u); // the sparse skip was exercised where it matters
}

TEST(CudaAdam, FastModeStepsMatchTheHostAdam) {
    REQUIRE_GPU();
    expect_adam_matches_host(false);
}

TEST(CudaAdam, DeterministicModeStepsMatchTheHostAdam) {
    REQUIRE_GPU();
    expect_adam_matches_host(true);
}

} // namespace
} // namespace nbvh
