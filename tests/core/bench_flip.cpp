// LDR-FLIP time of one image pair at the study's image size (not a test): flip_ldr (both images
// filtered) against FlipReference::compare (the reference prepared once, as the study and `nbvh
// converge` use it). Prints the median of 7 after one warm-up, the mean FLIP of both (equal) and the
// threads the filters may use (min(8, hardware threads)).
// Usage: nbvh_bench_flip [WIDTH HEIGHT]   (default 960 540)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

#include "engine/core/flip.h"

using namespace nbvh;

namespace {

template <class F>
double median_ms(const F& fn) {
    fn(); // warm-up
    std::vector<double> ms;
    for (int k = 0; k < 7; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        fn();
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(ms.begin(), ms.end());
    return ms[ms.size() / 2];
}

} // namespace

int main(int argc, char** argv) {
    const int w = argc > 2 ? std::atoi(argv[1]) : 960, h = argc > 2 ? std::atoi(argv[2]) : 540;
    if (w <= 0 || h <= 0 || w > 16384 || h > 16384) {
        std::fprintf(stderr, "usage: nbvh_bench_flip [WIDTH HEIGHT]\n");
        return 2;
    }
    // A noisy test image of a smooth reference (a rendered pair's kind of difference).
    Image ref(w, h, 4), test(w, h, 4);
    uint32_t s = 1u;
    auto next = [&] { s = s * 1664525u + 1013904223u; return float(s >> 8) / float(1u << 24); };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                const float v = 0.5f + 0.4f * float((x * (c + 1) + y) % 97) / 97.0f;
                ref.at(x, y)[c] = v;
                test.at(x, y)[c] = std::clamp(v + 0.1f * (next() - 0.5f), 0.0f, 1.0f);
            }
    float a = 0.0f, b = 0.0f;
    const double full = median_ms([&] { a = flip_ldr(ref, test).mean; });
    const FlipReference prepared(ref);
    const double half = median_ms([&] { b = prepared.compare(test).mean; });
    const double prep = median_ms([&] { (void)FlipReference(ref); });
    std::printf("LDR-FLIP %dx%d, up to %u threads: flip_ldr %.1f ms, FlipReference::compare %.1f ms (%.2fx), "
                "preparing the reference %.1f ms; mean %.6f / %.6f\n",
                w, h, std::min(8u, std::max(1u, std::thread::hardware_concurrency())), full, half, full / half, prep,
                double(a), double(b));
    return a == b ? 0 : 1;
}
