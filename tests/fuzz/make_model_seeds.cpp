// make_model_seeds DIR: writes the model fuzz target's seeds (model_seeds.h) into DIR, created if needed.
// Built in every build; scripts/fuzz.sh runs it so the corpus always follows the current model format.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "engine/core/error.h"
#include "tests/fuzz/model_seeds.h"

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
        return 2;
    }
    try {
        const std::filesystem::path dir = argv[1];
        std::filesystem::create_directories(dir);
        const std::vector<nbvh::fuzz::Seed> seeds = nbvh::fuzz::model_seeds();
        for (const nbvh::fuzz::Seed& s : seeds) {
            std::ofstream out(dir / s.name, std::ios::binary | std::ios::trunc);
            out.write(reinterpret_cast<const char*>(s.bytes.data()), std::streamsize(s.bytes.size()));
            if (!out) throw nbvh::Error("cannot write " + (dir / s.name).string());
        }
        std::printf("make_model_seeds: %zu seeds in %s\n", seeds.size(), dir.c_str());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "make_model_seeds: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
