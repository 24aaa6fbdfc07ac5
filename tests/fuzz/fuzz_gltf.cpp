// libFuzzer target: the glTF loader (fuzz_targets.h gltf_input). Built with -DNBVH_LIBFUZZER=ON;
// run through scripts/fuzz.sh gltf SECONDS.
#include "engine/core/log.h"
#include "tests/fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    nbvh::set_log_level(nbvh::LogLevel::quiet);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    (void)nbvh::fuzz::gltf_input({data, size});
    return 0;
}
