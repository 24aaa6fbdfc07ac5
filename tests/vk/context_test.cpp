// Context, buffers, images, pipelines, commands and timers on lavapipe with validation on.
#include "engine/vk/commands.h"
#include "engine/core/log.h"
#include "engine/vk/kernel_runner.h"

#include <gtest/gtest.h>

#include <cctype>
#include <numeric>

using namespace nbvh::vk;

namespace {

Context make_cpu_context() {
    ContextOptions options;
    options.device = DeviceChoice::cpu;
    options.validation = true;
    return Context(options);
}

struct SmokePush {
    uint32_t count;
    uint32_t offset;
};

PipelineDesc smoke_desc(uint32_t scale) {
    PipelineDesc d;
    d.shader = "tests/vk_smoke.comp";
    d.bindings = {{0, BindingType::storage_buffer}, {1, BindingType::storage_buffer}};
    d.spec = {{0, scale}};
    d.push_constant_bytes = sizeof(SmokePush);
    return d;
}

} // namespace

TEST(VkContext, CpuDeviceFeatures) {
    Context ctx = make_cpu_context();
    const DeviceFeatures& f = ctx.features();
    std::printf("%s\n", f.summary().c_str());
    EXPECT_TRUE(ctx.validation_enabled()) << "install vulkan-validationlayers: shader tests need it";
    EXPECT_TRUE(f.is_cpu);
    EXPECT_FALSE(f.device_name.empty());
    EXPECT_GE(f.api_version, uint32_t(VK_API_VERSION_1_2));
    EXPECT_TRUE(f.scalar_layout);
    EXPECT_GT(f.subgroup_size, 0u);
    EXPECT_LE(f.min_subgroup_size, f.subgroup_size);
    EXPECT_GE(f.max_subgroup_size, f.subgroup_size);
    EXPECT_GE(f.max_shared_memory, 16384u);
    EXPECT_GE(f.max_storage_buffer_range, uint64_t(1) << 27);
    EXPECT_GE(f.max_push_constants, 128u);
    EXPECT_GT(f.max_workgroup_count[0], 0u);
    if (f.timestamp_valid_bits) {
        EXPECT_GT(f.timestamp_period, 0.0f);
    }
    if (!f.coop_matrix_nv) {
        EXPECT_TRUE(f.coop_matrix_shapes.empty());
    }
    EXPECT_NE(f.summary().find(f.device_name), std::string::npos);

    const std::string name = f.device_name;
    Context moved = std::move(ctx); // move-only RAII keeps working after a move
    EXPECT_EQ(moved.features().device_name, name);
    EXPECT_EQ(moved.validation_message_count(), 0);
}

TEST(VkContext, DeviceChoiceParsing) {
    EXPECT_EQ(parse_device_choice("auto"), DeviceChoice::automatic);
    EXPECT_EQ(parse_device_choice("gpu"), DeviceChoice::gpu);
    EXPECT_EQ(parse_device_choice("cpu"), DeviceChoice::cpu);
    EXPECT_THROW(parse_device_choice("GPU0"), nbvh::Error);
    EXPECT_THROW(parse_device_choice(""), nbvh::Error);
    EXPECT_THROW(parse_device_choice("gpu:0"), nbvh::Error) << "an index is parse_device_spec's";
}

TEST(VkContext, DeviceSpecParsing) {
    for (const char* plain : {"auto", "gpu", "cpu"}) {
        const DeviceSpec s = parse_device_spec(plain);
        EXPECT_EQ(s.choice, parse_device_choice(plain));
        EXPECT_EQ(s.gpu_index, -1);
    }
    EXPECT_EQ(parse_device_spec("gpu:0").choice, DeviceChoice::gpu);
    EXPECT_EQ(parse_device_spec("gpu:0").gpu_index, 0);
    EXPECT_EQ(parse_device_spec("gpu:7").gpu_index, 7);
    EXPECT_EQ(parse_device_spec("gpu:0012").gpu_index, 12);
    for (const char* bad :
         {"gpu:", "gpu:-1", "gpu:x", "gpu:1x", "gpu: 1", "gpu:99999", "cpu:0", "gpu0", "GPU:1"})
        EXPECT_THROW(parse_device_spec(bad), nbvh::Error) << bad;
    try { // every unknown word is told every form, gpu:N included
        parse_device_spec("gpu0");
        ADD_FAILURE() << "gpu0 was accepted";
    } catch (const nbvh::Error& e) {
        EXPECT_NE(std::string(e.what()).find("gpu:N"), std::string::npos) << e.what();
    }
    ContextOptions o;
    o.set_device("gpu:3");
    EXPECT_EQ(o.device, DeviceChoice::gpu);
    EXPECT_EQ(o.gpu_index, 3);
    o.set_device("cpu");
    EXPECT_EQ(o.device, DeviceChoice::cpu);
    EXPECT_EQ(o.gpu_index, -1);
}

// The device UUID (how `nbvh study --device gpu:N` finds the same GPU in CUDA) is reported in CUDA's form.
TEST(VkContext, DeviceUuidIsFormattedLikeCuda) {
    Context ctx = make_cpu_context();
    const std::string& u = ctx.features().device_uuid;
    ASSERT_EQ(u.size(), 36u) << u;
    for (size_t i = 0; i < u.size(); ++i) {
        if (i == 8 || i == 13 || i == 18 || i == 23)
            EXPECT_EQ(u[i], '-') << u;
        else
            EXPECT_TRUE(std::isxdigit(static_cast<unsigned char>(u[i])) &&
                        !std::isupper(static_cast<unsigned char>(u[i])))
                << u;
    }
    EXPECT_NE(ctx.features().summary().find(u), std::string::npos);
}

// gpu:N counts GPUs only: beyond the last one (every one, on a machine with lavapipe alone) it is a
// one-line error naming the devices, never another device.
TEST(VkContext, GpuIndexBeyondTheGpusIsAClearError) {
    ContextOptions o;
    o.set_device("gpu:63");
    o.validation = false;
    try {
        Context ctx(o);
        ADD_FAILURE() << "gpu:63 picked " << ctx.features().device_name;
    } catch (const nbvh::Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("--device gpu:63"), std::string::npos) << m;
        EXPECT_NE(m.find("found:"), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << "one line: " << m;
    }
}

TEST(VkBuffer, RoundTripDeviceAndHost) {
    Context ctx = make_cpu_context();
    std::vector<uint32_t> data(1000);
    std::iota(data.begin(), data.end(), 17u);
    for (MemoryKind kind : {MemoryKind::device, MemoryKind::host}) {
        Buffer b(ctx, data.size() * 4, kind, 0, "round trip");
        b.upload(data);
        EXPECT_EQ(b.download<uint32_t>(data.size()), data);
        // Partial upload at an offset, partial download.
        std::vector<uint32_t> patch = {1, 2, 3};
        b.upload(patch, 40);
        std::vector<uint32_t> back = b.download<uint32_t>(5, 36);
        EXPECT_EQ(back, (std::vector<uint32_t>{data[9], 1, 2, 3, data[13]}));
        b.fill(0xDEADBEEFu);
        std::vector<uint32_t> filled = b.download<uint32_t>(data.size());
        EXPECT_TRUE(std::all_of(filled.begin(), filled.end(), [](uint32_t w) { return w == 0xDEADBEEFu; }));
    }
    Buffer empty(ctx, 0, MemoryKind::device, 0, "empty"); // legal: zero-sized arrays are common
    EXPECT_EQ(empty.size(), 0u);
    Buffer moved = std::move(empty);
    EXPECT_TRUE(bool(moved));
    EXPECT_FALSE(bool(empty));
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

TEST(VkImage, RoundTrip) {
    Context ctx = make_cpu_context();
    std::vector<float> texels(7 * 5 * 4);
    std::iota(texels.begin(), texels.end(), 0.25f);
    Image img(ctx, 7, 5, ImageFormat::rgba32f, image_sampled | image_storage, "film");
    img.upload(texels.data(), texels.size() * 4);
    std::vector<float> back(texels.size());
    img.download(back.data(), back.size() * 4);
    EXPECT_EQ(back, texels);
    std::vector<uint8_t> rgba(3 * 2 * 4, 200);
    Image srgb(ctx, 3, 2, ImageFormat::rgba8_srgb, image_sampled, "base color");
    srgb.upload(rgba.data(), rgba.size());
    Sampler sampler(ctx, {.linear = true, .repeat = false});
    EXPECT_NE(sampler.handle(), VK_NULL_HANDLE);
    EXPECT_THROW(Image(ctx, 0, 4, ImageFormat::r32f, image_storage), nbvh::Error);
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

TEST(VkPipeline, DispatchSpecConstantsAndPush) {
    KernelRunner run;
    std::vector<uint32_t> in(1000);
    std::iota(in.begin(), in.end(), 0u);
    Buffer a = run.input(in);
    Buffer b = run.output<uint32_t>(in.size() + 10); // tail stays 0: the kernel bounds-checks
    run.dispatch({.shader = "tests/vk_smoke.comp", .bindings = {&a, &b}, .items = in.size(), .group_size = 64,
                  .push = push_bytes(SmokePush{uint32_t(in.size()), 7u}), .spec = {{0, 3u}}});
    std::vector<uint32_t> out = run.read<uint32_t>(b, in.size() + 10);
    for (uint32_t i = 0; i < in.size(); ++i) ASSERT_EQ(out[i], 3u * i + 7u) << i;
    for (size_t i = in.size(); i < out.size(); ++i) EXPECT_EQ(out[i], 0u);
    EXPECT_EQ(run.validation_messages(), 0);
}

TEST(VkPipeline, BindingBeyondStorageRangeIsAnError) {
    Context ctx = make_cpu_context();
    ComputePipeline pipe(ctx, smoke_desc(2));
    DescriptorSet set(ctx, pipe);
    Buffer small(ctx, 64, MemoryKind::device, 0, "small");
    EXPECT_THROW(set.bind(0, small, 0, ctx.features().max_storage_buffer_range + 4), nbvh::Error);
    EXPECT_THROW(ComputePipeline(ctx, PipelineDesc{.shader = "tests/no_such_shader.comp"}), nbvh::Error);
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

// Indirect dispatch, barriers, reuse of one command buffer, and GPU timestamps per pass name.
TEST(VkCommands, IndirectDispatchAndTimers) {
    Context ctx = make_cpu_context();
    ComputePipeline pipe(ctx, smoke_desc(2));
    const uint32_t n = 300;
    std::vector<uint32_t> in(n, 5u);
    Buffer a = make_buffer(ctx, in, "in");
    Buffer b(ctx, n * 4, MemoryKind::device, 0, "out");
    Buffer args(ctx, 12, MemoryKind::device, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, "args");
    DescriptorSet set(ctx, pipe);
    set.bind(0, a).bind(1, b);

    CommandBuffer cmd(ctx, "test");
    GpuTimer timer(ctx, 8);
    for (int round = 0; round < 2; ++round) { // the same command buffer, recorded twice
        cmd.begin();
        timer.reset(cmd.handle());
        cmd.fill(b, 0u).fill(args, (n + 63) / 64, 0, 4).fill(args, 1u, 4, 8);
        cmd.barrier(Barrier::transfer_to_compute);
        cmd.begin_pass("smoke", &timer).bind(pipe, set).push(SmokePush{n, uint32_t(round)});
        cmd.dispatch_indirect(args).end_pass();
        cmd.barrier(Barrier::compute_to_compute);
        cmd.begin_pass("smoke", &timer).dispatch(1).end_pass(); // same name: times add up
        cmd.begin_pass("other", &timer).end_pass();
        cmd.barrier(Barrier::compute_to_transfer);
        cmd.submit_and_wait();
        std::vector<uint32_t> out = b.download<uint32_t>(n);
        for (uint32_t i = 0; i < n; ++i) ASSERT_EQ(out[i], 10u + uint32_t(round)) << i;

        auto times = timer.results();
        if (ctx.features().timestamp_valid_bits) {
            ASSERT_EQ(times.size(), 2u);
            EXPECT_EQ(times[0].first, "smoke");
            EXPECT_EQ(times[1].first, "other");
            for (auto& [name, ms] : times) {
                EXPECT_GE(ms, 0.0) << name;  // end timestamp not before begin
                EXPECT_LT(ms, 60000.0) << name; // no wrap-around garbage
            }
        }
    }
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

// What a presenter's frames in flight use: two command buffers ordered by a semaphore (the second
// waits for the first on the GPU, only its own fence is waited for), column ranges of two buffers
// copied into one image, and a layout transition of an image the layer does not own.
TEST(VkCommands, SemaphoreOrderedSubmissionsAndImageCopies) {
    Context ctx = make_cpu_context();
    const uint32_t w = 6, h = 3;
    std::vector<uint32_t> left(w * h), right(w * h);
    for (uint32_t i = 0; i < w * h; ++i) left[i] = 0x01000000u + i, right[i] = 0x02000000u + i;
    Buffer a = make_buffer(ctx, left, "left"), b(ctx, w * h * 4, MemoryKind::device, 0, "right");
    Buffer staging = make_buffer(ctx, right, "right staging");
    Image film(ctx, w, h, ImageFormat::rgba8, image_sampled, "film");
    Semaphore ready(ctx, "right ready");
    CommandBuffer first(ctx, "first"), second(ctx, "second");
    first.begin().copy(staging, b, w * h * 4).submit({.signal = ready.handle()});
    second.begin()
        .copy_to_image(a, 0, w, film, 0, 0, 2, h)      // columns [0, 2) from `left`
        .copy_to_image(b, 2 * 4, w, film, 2, 0, w - 2, h) // columns [2, w) from `right`
        .barrier(Barrier::transfer_to_transfer);
    second.submit({.wait = ready.handle(), .wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT});
    EXPECT_TRUE(second.in_flight());
    second.wait();
    EXPECT_FALSE(second.in_flight());
    std::vector<uint32_t> back(w * h);
    film.download(back.data(), back.size() * 4);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) EXPECT_EQ(back[y * w + x], (x < 2 ? left : right)[y * w + x]) << x << "," << y;
    // A transition through TRANSFER_DST and back (what the presenter does to swapchain images).
    second.begin()
        .transition(film.handle(), VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                    VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT)
        .transition(film.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                    VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                    VK_ACCESS_TRANSFER_READ_BIT)
        .submit_and_wait();
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

// The messenger counts what the layer reports (so the "zero messages" checks everywhere can fail):
// a fill whose size is not a multiple of 4 is a validation error (recorded, never submitted).
TEST(VkContext, ValidationMessagesAreCounted) {
    Context ctx = make_cpu_context();
    ASSERT_TRUE(ctx.validation_enabled());
    Buffer buffer(ctx, 64, MemoryKind::device, 0, "target");
    CommandBuffer cmd(ctx, "invalid on purpose");
    cmd.begin();
    nbvh::set_log_level(nbvh::LogLevel::quiet);
    vkCmdFillBuffer(cmd.handle(), buffer.handle(), 0, 6, 0u);
    nbvh::set_log_level(nbvh::LogLevel::info);
    cmd.end();
    EXPECT_GT(ctx.validation_message_count(), 0);
    ctx.reset_validation_message_count();
    EXPECT_EQ(ctx.validation_message_count(), 0);
}
