// Command recording for compute work: a reusable command buffer with its own pool and fence,
// dispatches, barriers, debug labels and timed passes; semaphores and image copies / layout
// transitions for a presenter (app/viewer: frames in flight, one CommandBuffer + Semaphore per frame).
//
//   CommandBuffer cmd(ctx, "frame");
//   GpuTimer timer(ctx);
//   cmd.begin();
//   timer.reset(cmd);
//   cmd.begin_pass("passes/trace.comp", &timer);      // debug label + timestamp pair
//   cmd.bind(trace, trace_set).push(trace, push).dispatch_items(ray_count, 64);
//   cmd.end_pass();
//   cmd.barrier(Barrier::compute_to_compute);
//   ...
//   cmd.submit_and_wait();                               // ends recording if still open
//   for (auto& [name, ms] : timer.results()) ...
#pragma once
#include "buffer.h"
#include "image.h"
#include "pipeline.h"

#include <string>
#include <utility>
#include <vector>

namespace nbvh::vk {

class GpuTimer;

// Memory + execution dependencies between the kinds of work a compute renderer does. Global memory
// barriers (not per buffer): simpler, and as fast on current drivers.
enum class Barrier {
    compute_to_compute,  // shader writes -> shader reads/writes
    compute_to_indirect, // shader writes (counters, dispatch args) -> vkCmdDispatchIndirect + shader reads
    transfer_to_compute, // fill/copy -> shader reads/writes
    compute_to_transfer, // shader writes -> copy/fill
    compute_to_host,     // shader/transfer writes -> host reads of a mapped buffer after the fence
    transfer_to_transfer, // copy writes -> copy/blit reads and writes (images in GENERAL layout included)
};

// A binary semaphore (GPU-GPU ordering between submissions and presentation).
class Semaphore {
public:
    Semaphore() = default;
    explicit Semaphore(const Context& ctx, const std::string& name = "semaphore");
    ~Semaphore();
    Semaphore(Semaphore&& other) noexcept;
    Semaphore& operator=(Semaphore&& other) noexcept;
    Semaphore(const Semaphore&) = delete;
    Semaphore& operator=(const Semaphore&) = delete;
    VkSemaphore handle() const { return semaphore_; }

private:
    const Context* ctx_ = nullptr;
    VkSemaphore semaphore_ = VK_NULL_HANDLE;
};

// What a submission waits for and signals besides its fence (VK_NULL_HANDLE: nothing).
struct SubmitSync {
    VkSemaphore wait = VK_NULL_HANDLE;
    VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkSemaphore signal = VK_NULL_HANDLE;
};

class CommandBuffer {
public:
    CommandBuffer() = default;
    explicit CommandBuffer(const Context& ctx, const std::string& name = "commands");
    ~CommandBuffer();
    CommandBuffer(CommandBuffer&& other) noexcept;
    CommandBuffer& operator=(CommandBuffer&& other) noexcept;
    CommandBuffer(const CommandBuffer&) = delete;
    CommandBuffer& operator=(const CommandBuffer&) = delete;

    // Start recording (waits for a previous submission of this buffer, then resets it).
    CommandBuffer& begin();
    CommandBuffer& end();
    // Submit (ending recording if needed); wait() blocks until the GPU is done. `sync` adds a semaphore
    // to wait for (at its stage) and one to signal. A submission's fence also covers everything
    // submitted to the queue before it (Vulkan's fence-signal scope).
    void submit(const SubmitSync& sync = {});
    void wait();
    bool in_flight() const { return in_flight_; }
    void submit_and_wait() {
        submit();
        wait();
    }

    CommandBuffer& bind(const ComputePipeline& pipeline, const DescriptorSet& set);
    // Push constants of the pipeline bound last (size <= its push_constant_bytes).
    CommandBuffer& push(const void* data, uint32_t bytes);
    template <class T> CommandBuffer& push(const T& value) { return push(&value, uint32_t(sizeof(T))); }
    CommandBuffer& dispatch(uint32_t groups_x, uint32_t groups_y = 1, uint32_t groups_z = 1);
    // ceil(items / group_size) groups along x (a no-op for 0 items). Checks the device's group limit.
    CommandBuffer& dispatch_items(uint64_t items, uint32_t group_size);
    // Arguments (3 x uint32 groups: VkDispatchIndirectCommand) read from `args` at `offset`;
    // the buffer needs VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT.
    CommandBuffer& dispatch_indirect(const Buffer& args, VkDeviceSize offset = 0);
    CommandBuffer& barrier(Barrier kind);
    CommandBuffer& fill(const Buffer& buffer, uint32_t word, VkDeviceSize offset = 0,
                        VkDeviceSize bytes = VK_WHOLE_SIZE);
    CommandBuffer& copy(const Buffer& src, const Buffer& dst, VkDeviceSize bytes, VkDeviceSize src_offset = 0,
                        VkDeviceSize dst_offset = 0);
    // Texels of rows `row_length` texels apart, starting at byte `src_offset` of `src`, into the
    // width x height rectangle at (x, y) of `dst` (GENERAL layout before and after, as every Image; the
    // copy itself goes through TRANSFER_DST_OPTIMAL, with the barriers that takes).
    CommandBuffer& copy_to_image(const Buffer& src, VkDeviceSize src_offset, uint32_t row_length, const Image& dst,
                                 uint32_t x, uint32_t y, uint32_t width, uint32_t height);
    // A layout transition of a colour image this layer does not own (a swapchain image).
    CommandBuffer& transition(VkImage image, VkImageLayout from, VkImageLayout to, VkPipelineStageFlags src_stage,
                              VkAccessFlags src_access, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access);

    // A named region: debug label (RenderDoc/Nsight) and, with a timer, a timestamp pair. Nestable
    // for labels; the timer sums nested regions independently.
    // `tag`: a number kept with the pass's timestamps (GpuTimer::slot_results), e.g. a path depth.
    CommandBuffer& begin_pass(const std::string& name, GpuTimer* timer = nullptr, uint32_t tag = 0);
    CommandBuffer& end_pass();

    VkCommandBuffer handle() const { return cmd_; }
    const Context& context() const { return *ctx_; }

private:
    void destroy();
    const Context* ctx_ = nullptr;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkCommandBuffer cmd_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkPipelineLayout bound_layout_ = VK_NULL_HANDLE;
    uint32_t bound_push_bytes_ = 0;
    bool recording_ = false;
    bool in_flight_ = false;
    std::vector<std::pair<GpuTimer*, uint32_t>> open_passes_; // (timer, its pass slot)
};

// GPU timestamps per named pass, in milliseconds, summed over repeats of the same name. One timer per
// command buffer recording: reset() at the start of the recording, results() after the wait.
class GpuTimer {
public:
    GpuTimer() = default;
    explicit GpuTimer(const Context& ctx, uint32_t max_passes = 256);
    ~GpuTimer();
    GpuTimer(GpuTimer&& other) noexcept;
    GpuTimer& operator=(GpuTimer&& other) noexcept;
    GpuTimer(const GpuTimer&) = delete;
    GpuTimer& operator=(const GpuTimer&) = delete;

    bool available() const { return pool_ != VK_NULL_HANDLE; } // false when the queue has no timestamps
    void reset(VkCommandBuffer cmd);
    // Returns a slot for end(); passes beyond max_passes are silently not timed. `tag` is kept with the
    // slot (slot_results).
    uint32_t begin(VkCommandBuffer cmd, const std::string& name, uint32_t tag = 0);
    void end(VkCommandBuffer cmd, uint32_t slot);
    // (pass name, milliseconds) in order of first appearance. Blocks until the results are ready.
    std::vector<std::pair<std::string, double>> results() const;
    // Every timed slot in recording order: its pass name, tag and milliseconds. Blocks likewise.
    struct SlotResult {
        std::string name;
        uint32_t tag = 0;
        double ms = 0.0;
    };
    std::vector<SlotResult> slot_results() const;
    double total_ms() const;

private:
    const Context* ctx_ = nullptr;
    VkQueryPool pool_ = VK_NULL_HANDLE;
    uint32_t max_passes_ = 0;
    std::vector<std::string> names_; // one per used slot
    std::vector<uint32_t> tags_;     // one per used slot
};

} // namespace nbvh::vk
