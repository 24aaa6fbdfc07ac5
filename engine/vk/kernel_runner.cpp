#include "kernel_runner.h"

namespace nbvh::vk {

KernelRunner::KernelRunner(DeviceChoice device, bool validation) : ctx_([&] {
    ContextOptions options;
    options.device = device;
    options.validation = validation;
    return options;
}()) {}

double KernelRunner::dispatch(const KernelRun& run) {
    PipelineDesc desc;
    desc.shader = run.shader;
    for (uint32_t i = 0; i < run.bindings.size(); ++i) desc.bindings.push_back({i, BindingType::storage_buffer, 1});
    desc.spec = run.spec;
    desc.push_constant_bytes = uint32_t((run.push.size() + 3) / 4 * 4);
    ComputePipeline pipeline(ctx_, desc);

    DescriptorSet set(ctx_, pipeline);
    for (uint32_t i = 0; i < run.bindings.size(); ++i) {
        NBVH_CHECK_MSG(run.bindings[i] && *run.bindings[i], "KernelRun binding is null");
        set.bind(i, *run.bindings[i]);
    }

    std::vector<uint8_t> push = run.push;
    push.resize(desc.push_constant_bytes, 0);
    GpuTimer timer(ctx_, 1);
    CommandBuffer cmd(ctx_, run.shader);
    cmd.begin();
    timer.reset(cmd.handle());
    cmd.begin_pass(run.shader, &timer);
    cmd.bind(pipeline, set);
    if (!push.empty()) cmd.push(push.data(), uint32_t(push.size()));
    cmd.dispatch_items(run.items, run.group_size);
    cmd.end_pass();
    cmd.barrier(Barrier::compute_to_transfer);
    cmd.submit_and_wait();
    return timer.total_ms();
}

} // namespace nbvh::vk
