#include "commands.h"

#include "engine/core/log.h"

#include <algorithm>
#include <utility>

namespace nbvh::vk {

CommandBuffer::CommandBuffer(const Context& ctx, const std::string& name) : ctx_(&ctx) {
    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = ctx.queue_family();
    NBVH_VK_CHECK(vkCreateCommandPool(ctx.device(), &pool, nullptr, &pool_));
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    NBVH_VK_CHECK(vkAllocateCommandBuffers(ctx.device(), &alloc, &cmd_));
    VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    NBVH_VK_CHECK(vkCreateFence(ctx.device(), &fence, nullptr, &fence_));
    ctx.set_name(VK_OBJECT_TYPE_COMMAND_BUFFER, cmd_, name);
}

CommandBuffer::~CommandBuffer() { destroy(); }

CommandBuffer::CommandBuffer(CommandBuffer&& o) noexcept { *this = std::move(o); }

CommandBuffer& CommandBuffer::operator=(CommandBuffer&& o) noexcept {
    if (this != &o) {
        destroy();
        ctx_ = o.ctx_;
        pool_ = std::exchange(o.pool_, VK_NULL_HANDLE);
        cmd_ = std::exchange(o.cmd_, VK_NULL_HANDLE);
        fence_ = std::exchange(o.fence_, VK_NULL_HANDLE);
        bound_layout_ = o.bound_layout_;
        bound_push_bytes_ = o.bound_push_bytes_;
        recording_ = std::exchange(o.recording_, false);
        in_flight_ = std::exchange(o.in_flight_, false);
        open_passes_ = std::move(o.open_passes_);
    }
    return *this;
}

void CommandBuffer::destroy() {
    if (!ctx_ || !pool_) return;
    if (in_flight_) wait();
    vkDestroyFence(ctx_->device(), fence_, nullptr);
    vkDestroyCommandPool(ctx_->device(), pool_, nullptr); // frees cmd_
    pool_ = VK_NULL_HANDLE;
    cmd_ = VK_NULL_HANDLE;
    fence_ = VK_NULL_HANDLE;
}

CommandBuffer& CommandBuffer::begin() {
    if (in_flight_) wait();
    NBVH_CHECK_MSG(!recording_, "begin() while already recording");
    NBVH_VK_CHECK(vkResetCommandBuffer(cmd_, 0));
    VkCommandBufferBeginInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    NBVH_VK_CHECK(vkBeginCommandBuffer(cmd_, &info));
    recording_ = true;
    bound_layout_ = VK_NULL_HANDLE;
    bound_push_bytes_ = 0;
    return *this;
}

CommandBuffer& CommandBuffer::end() {
    NBVH_CHECK_MSG(recording_, "end() without begin()");
    NBVH_CHECK_MSG(open_passes_.empty(), "end() with a begin_pass() still open");
    NBVH_VK_CHECK(vkEndCommandBuffer(cmd_));
    recording_ = false;
    return *this;
}

void CommandBuffer::submit(const SubmitSync& sync) {
    if (recording_) end();
    NBVH_CHECK_MSG(!in_flight_, "submit() of a command buffer still in flight");
    NBVH_VK_CHECK(vkResetFences(ctx_->device(), 1, &fence_));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd_;
    if (sync.wait) {
        submit.waitSemaphoreCount = 1;
        submit.pWaitSemaphores = &sync.wait;
        submit.pWaitDstStageMask = &sync.wait_stage;
    }
    if (sync.signal) {
        submit.signalSemaphoreCount = 1;
        submit.pSignalSemaphores = &sync.signal;
    }
    NBVH_VK_CHECK(vkQueueSubmit(ctx_->queue(), 1, &submit, fence_));
    in_flight_ = true;
}

void CommandBuffer::wait() {
    if (!in_flight_) return;
    NBVH_VK_CHECK(vkWaitForFences(ctx_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
    in_flight_ = false;
}

CommandBuffer& CommandBuffer::bind(const ComputePipeline& pipeline, const DescriptorSet& set) {
    NBVH_CHECK(recording_);
    vkCmdBindPipeline(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.handle());
    VkDescriptorSet s = set.handle();
    vkCmdBindDescriptorSets(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout(), 0, 1, &s, 0, nullptr);
    bound_layout_ = pipeline.layout();
    bound_push_bytes_ = pipeline.desc().push_constant_bytes;
    return *this;
}

CommandBuffer& CommandBuffer::push(const void* data, uint32_t bytes) {
    NBVH_CHECK_MSG(bound_layout_ != VK_NULL_HANDLE, "push() before bind()");
    NBVH_CHECK_MSG(bytes <= bound_push_bytes_ && bytes % 4 == 0,
                   "push constants larger than the pipeline's push_constant_bytes");
    vkCmdPushConstants(cmd_, bound_layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, bytes, data);
    return *this;
}

CommandBuffer& CommandBuffer::dispatch(uint32_t x, uint32_t y, uint32_t z) {
    NBVH_CHECK(recording_);
    const uint32_t* max = ctx_->features().max_workgroup_count;
    NBVH_CHECK_MSG(x <= max[0] && y <= max[1] && z <= max[2], "dispatch exceeds maxComputeWorkGroupCount");
    if (x && y && z) vkCmdDispatch(cmd_, x, y, z);
    return *this;
}

CommandBuffer& CommandBuffer::dispatch_items(uint64_t items, uint32_t group_size) {
    NBVH_CHECK(group_size > 0);
    uint64_t groups = (items + group_size - 1) / group_size;
    NBVH_CHECK_MSG(groups <= ctx_->features().max_workgroup_count[0],
                   "too many items for one 1D dispatch (split it or use 2D)");
    return dispatch(uint32_t(groups));
}

CommandBuffer& CommandBuffer::dispatch_indirect(const Buffer& args, VkDeviceSize offset) {
    NBVH_CHECK(recording_);
    NBVH_CHECK_MSG(offset % 4 == 0 && offset + 12 <= args.size(), "indirect arguments out of range");
    vkCmdDispatchIndirect(cmd_, args.handle(), offset);
    return *this;
}

CommandBuffer& CommandBuffer::barrier(Barrier kind) {
    NBVH_CHECK(recording_);
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    VkPipelineStageFlags src = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, dst = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    switch (kind) {
    case Barrier::compute_to_compute:
        b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
        b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
        break;
    case Barrier::compute_to_indirect:
        b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
        b.dstAccessMask = VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
        dst = VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
        break;
    case Barrier::transfer_to_compute:
        b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
        src = VK_PIPELINE_STAGE_TRANSFER_BIT;
        dst = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;
        break;
    case Barrier::compute_to_transfer:
        b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT;
        b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
        dst = VK_PIPELINE_STAGE_TRANSFER_BIT;
        break;
    case Barrier::compute_to_host:
        b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
        b.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        src = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
        dst = VK_PIPELINE_STAGE_HOST_BIT;
        break;
    case Barrier::transfer_to_transfer:
        b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
        src = dst = VK_PIPELINE_STAGE_TRANSFER_BIT;
        break;
    }
    vkCmdPipelineBarrier(cmd_, src, dst, 0, 1, &b, 0, nullptr, 0, nullptr);
    return *this;
}

CommandBuffer& CommandBuffer::fill(const Buffer& buffer, uint32_t word, VkDeviceSize offset, VkDeviceSize bytes) {
    NBVH_CHECK(recording_);
    if (bytes == VK_WHOLE_SIZE) bytes = (std::max<VkDeviceSize>(buffer.size(), 4) - offset) & ~VkDeviceSize(3);
    NBVH_CHECK_MSG(offset % 4 == 0 && bytes % 4 == 0, "fill offset and size must be multiples of 4");
    if (bytes) vkCmdFillBuffer(cmd_, buffer.handle(), offset, bytes, word);
    return *this;
}

CommandBuffer& CommandBuffer::copy(const Buffer& src, const Buffer& dst, VkDeviceSize bytes, VkDeviceSize src_offset,
                                   VkDeviceSize dst_offset) {
    NBVH_CHECK(recording_);
    NBVH_CHECK_MSG(src_offset + bytes <= src.size() && dst_offset + bytes <= dst.size(), "copy out of range");
    VkBufferCopy region{src_offset, dst_offset, bytes};
    if (bytes) vkCmdCopyBuffer(cmd_, src.handle(), dst.handle(), 1, &region);
    return *this;
}

CommandBuffer& CommandBuffer::copy_to_image(const Buffer& src, VkDeviceSize src_offset, uint32_t row_length,
                                            const Image& dst, uint32_t x, uint32_t y, uint32_t width,
                                            uint32_t height) {
    NBVH_CHECK(recording_);
    NBVH_CHECK_MSG(x + width <= dst.width() && y + height <= dst.height() && width <= row_length,
                   "image copy out of range");
    const VkDeviceSize texel = texel_bytes(dst.format());
    NBVH_CHECK_MSG(height == 0 || src_offset + (VkDeviceSize(height - 1) * row_length + width) * texel <= src.size(),
                   "image copy reads past the buffer");
    VkBufferImageCopy region{};
    region.bufferOffset = src_offset;
    region.bufferRowLength = row_length;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageOffset = {int32_t(x), int32_t(y), 0};
    region.imageExtent = {width, height, 1};
    if (width == 0 || height == 0) return *this;
    // GENERAL -> TRANSFER_DST_OPTIMAL -> GENERAL around the copy (the layer's convention, image.h).
    const VkPipelineStageFlags all = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, t = VK_PIPELINE_STAGE_TRANSFER_BIT;
    const VkAccessFlags rw = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    transition(dst.handle(), VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, all, rw, t,
               VK_ACCESS_TRANSFER_WRITE_BIT);
    vkCmdCopyBufferToImage(cmd_, src.handle(), dst.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    transition(dst.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL, t,
               VK_ACCESS_TRANSFER_WRITE_BIT, all, rw);
    return *this;
}

CommandBuffer& CommandBuffer::transition(VkImage image, VkImageLayout from, VkImageLayout to,
                                         VkPipelineStageFlags src_stage, VkAccessFlags src_access,
                                         VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) {
    NBVH_CHECK(recording_);
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.oldLayout = from;
    b.newLayout = to;
    b.srcAccessMask = src_access;
    b.dstAccessMask = dst_access;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd_, src_stage, dst_stage, 0, 0, nullptr, 0, nullptr, 1, &b);
    return *this;
}

CommandBuffer& CommandBuffer::begin_pass(const std::string& name, GpuTimer* timer, uint32_t tag) {
    NBVH_CHECK(recording_);
    ctx_->begin_label(cmd_, name.c_str());
    uint32_t slot = timer ? timer->begin(cmd_, name, tag) : 0;
    open_passes_.push_back({timer, slot});
    return *this;
}

CommandBuffer& CommandBuffer::end_pass() {
    NBVH_CHECK_MSG(!open_passes_.empty(), "end_pass() without begin_pass()");
    auto [timer, slot] = open_passes_.back();
    open_passes_.pop_back();
    if (timer) timer->end(cmd_, slot);
    ctx_->end_label(cmd_);
    return *this;
}

// --- Semaphore ------------------------------------------------------------------------------------

Semaphore::Semaphore(const Context& ctx, const std::string& name) : ctx_(&ctx) {
    VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    NBVH_VK_CHECK(vkCreateSemaphore(ctx.device(), &info, nullptr, &semaphore_));
    ctx.set_name(VK_OBJECT_TYPE_SEMAPHORE, semaphore_, name);
}

Semaphore::~Semaphore() {
    if (ctx_ && semaphore_) vkDestroySemaphore(ctx_->device(), semaphore_, nullptr);
}

Semaphore::Semaphore(Semaphore&& o) noexcept { *this = std::move(o); }

Semaphore& Semaphore::operator=(Semaphore&& o) noexcept {
    if (this != &o) {
        if (ctx_ && semaphore_) vkDestroySemaphore(ctx_->device(), semaphore_, nullptr);
        ctx_ = o.ctx_;
        semaphore_ = std::exchange(o.semaphore_, VK_NULL_HANDLE);
    }
    return *this;
}

// --- GpuTimer -------------------------------------------------------------------------------------

GpuTimer::GpuTimer(const Context& ctx, uint32_t max_passes) : ctx_(&ctx), max_passes_(max_passes) {
    if (ctx.features().timestamp_valid_bits == 0 || max_passes == 0) return; // timing off, passes still run
    VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = 2 * max_passes;
    NBVH_VK_CHECK(vkCreateQueryPool(ctx.device(), &info, nullptr, &pool_));
}

GpuTimer::~GpuTimer() {
    if (ctx_ && pool_) vkDestroyQueryPool(ctx_->device(), pool_, nullptr);
}

GpuTimer::GpuTimer(GpuTimer&& o) noexcept { *this = std::move(o); }

GpuTimer& GpuTimer::operator=(GpuTimer&& o) noexcept {
    if (this != &o) {
        if (ctx_ && pool_) vkDestroyQueryPool(ctx_->device(), pool_, nullptr);
        ctx_ = o.ctx_;
        pool_ = std::exchange(o.pool_, VK_NULL_HANDLE);
        max_passes_ = o.max_passes_;
        names_ = std::move(o.names_);
        tags_ = std::move(o.tags_);
    }
    return *this;
}

void GpuTimer::reset(VkCommandBuffer cmd) {
    names_.clear();
    tags_.clear();
    if (pool_) vkCmdResetQueryPool(cmd, pool_, 0, 2 * max_passes_);
}

uint32_t GpuTimer::begin(VkCommandBuffer cmd, const std::string& name, uint32_t tag) {
    uint32_t slot = uint32_t(names_.size());
    if (!pool_ || slot >= max_passes_) return UINT32_MAX;
    names_.push_back(name);
    tags_.push_back(tag);
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, pool_, 2 * slot);
    return slot;
}

void GpuTimer::end(VkCommandBuffer cmd, uint32_t slot) {
    if (!pool_ || slot == UINT32_MAX) return;
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, 2 * slot + 1);
}

std::vector<GpuTimer::SlotResult> GpuTimer::slot_results() const {
    std::vector<SlotResult> out;
    if (!pool_ || names_.empty()) return out;
    std::vector<uint64_t> ticks(2 * names_.size());
    NBVH_VK_CHECK(vkGetQueryPoolResults(ctx_->device(), pool_, 0, uint32_t(ticks.size()),
                                        ticks.size() * sizeof(uint64_t), ticks.data(), sizeof(uint64_t),
                                        VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    const uint32_t bits = ctx_->features().timestamp_valid_bits;
    const uint64_t mask = bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
    const double ms_per_tick = double(ctx_->features().timestamp_period) * 1e-6;
    out.reserve(names_.size());
    for (size_t i = 0; i < names_.size(); ++i) {
        const uint64_t dt = (ticks[2 * i + 1] - ticks[2 * i]) & mask; // wrap-around safe
        out.push_back({names_[i], tags_[i], double(dt) * ms_per_tick});
    }
    return out;
}

std::vector<std::pair<std::string, double>> GpuTimer::results() const {
    std::vector<std::pair<std::string, double>> out;
    for (const SlotResult& r : slot_results()) {
        auto it = std::find_if(out.begin(), out.end(), [&](const auto& p) { return p.first == r.name; });
        if (it == out.end())
            out.push_back({r.name, r.ms});
        else
            it->second += r.ms;
    }
    return out;
}

double GpuTimer::total_ms() const {
    double sum = 0.0;
    for (const auto& [name, ms] : results()) sum += ms;
    return sum;
}

} // namespace nbvh::vk
