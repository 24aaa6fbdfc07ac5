// Runs one compute shader over N items and reads the results back: the harness of every shader test
// (intersection kernels, struct layouts, hash grid, MLP, ...). Defaults to the CPU device (lavapipe)
// with validation on, so a test can assert that the kernel ran without any validation message.
//
//   KernelRunner run;                                          // lavapipe + validation
//   Buffer in  = run.input(rays);                              // std::vector<GpuRay>
//   Buffer out = run.output<GpuHit>(rays.size());
//   run.dispatch({.shader = "tests/intersect.comp", .bindings = {&in, &out},
//                 .items = rays.size(), .group_size = 64, .push = push_bytes(params)});
//   std::vector<GpuHit> hits = run.read<GpuHit>(out, rays.size());
//   EXPECT_EQ(run.validation_messages(), 0);
//
// The shader declares its buffers as `layout(scalar, binding = i) buffer ...` for i = 0, 1, ... in the
// order of `bindings`, its workgroup as `layout(local_size_x = group_size) in;`, and bounds-checks
// gl_GlobalInvocationID.x against the item count it receives (push constant or buffer length).
#pragma once
#include "buffer.h"
#include "commands.h"
#include "context.h"
#include "pipeline.h"

#include <cstring>
#include <string>
#include <vector>

namespace nbvh::vk {

struct KernelRun {
    std::string shader;                  // e.g. "tests/intersect.comp"
    std::vector<const Buffer*> bindings; // storage buffers at bindings 0, 1, 2, ...
    uint64_t items = 1;                  // invocations wanted along x
    uint32_t group_size = 64;            // must equal the shader's local_size_x
    std::vector<uint8_t> push;           // push-constant bytes (<= 128), see push_bytes()
    std::vector<SpecConstant> spec;      // specialization constants
};

template <class T> std::vector<uint8_t> push_bytes(const T& value) {
    std::vector<uint8_t> bytes(sizeof(T));
    std::memcpy(bytes.data(), &value, sizeof(T));
    return bytes;
}

class KernelRunner {
public:
    // The CPU device keeps shader tests deterministic and runnable on every CI machine.
    explicit KernelRunner(DeviceChoice device = DeviceChoice::cpu, bool validation = true);

    Context& context() { return ctx_; }
    const DeviceFeatures& features() const { return ctx_.features(); }

    template <class T> Buffer input(const std::vector<T>& items, const std::string& name = "input") {
        return make_buffer(ctx_, items, name);
    }
    // A zero-filled output buffer of `count` items.
    template <class T> Buffer output(size_t count, const std::string& name = "output") {
        Buffer b(ctx_, count * sizeof(T), MemoryKind::device, 0, name);
        b.fill(0u);
        return b;
    }
    template <class T> std::vector<T> read(const Buffer& buffer, size_t count) const {
        return buffer.template download<T>(count);
    }

    // Builds the pipeline, dispatches once, waits; returns the GPU time in milliseconds
    // (0 when the device has no timestamps).
    double dispatch(const KernelRun& run);

    // Validation warnings + errors since the runner was made (must stay 0 in tests).
    int validation_messages() const { return ctx_.validation_message_count(); }

private:
    Context ctx_;
};

} // namespace nbvh::vk
