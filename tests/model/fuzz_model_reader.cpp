// Fuzz target for the .nbvh reader (and the official-tree importer).
//   libFuzzer: configure with -DNBVH_LIBFUZZER=ON and clang (adds -fsanitize=fuzzer,address and
//              defines NBVH_LIBFUZZER), then run ./nbvh_fuzz_model_reader CORPUS_DIR.
//   otherwise: a normal executable that mutates a valid tiny model deterministically N times (argument,
//              default 3000) and feeds each mutant to the target; registered as a unit test.
// The contract under test: any input either loads into a model that re-serialises and re-loads, or
// throws nbvh::Error. Anything else (another exception, a crash, a huge allocation) fails.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "engine/core/error.h"
#include "engine/neural/model_file.h"
#include "shaders/shared/neural_gpu.h"
#include "shaders/shared/neural_occupancy.h"
#include "tests/model/tiny_model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::span<const uint8_t> bytes(data, size);
    try {
        const nbvh::NeuralModel m = nbvh::parse_model(bytes, "fuzz");
        const nbvh::NbvhTree tree = m.tree();
        for (uint32_t l = 0; l < m.lod_count; ++l) (void)tree.to_gpu_layout(l);
        // Whatever loads must survive a round trip.
        const std::vector<uint8_t> again = nbvh::serialize_model(m);
        (void)nbvh::parse_model(again, "fuzz round trip");
    } catch (const nbvh::Error&) {
    }
    try {
        const std::vector<nbvh::NbvhNode> nodes = nbvh::import_official_tree(bytes, "fuzz");
        (void)nbvh::NbvhTree::from_nodes(nodes, 1).to_gpu_layout(0);
    } catch (const nbvh::Error&) {
    }
    return 0;
}

#ifndef NBVH_LIBFUZZER
namespace {

std::vector<uint8_t> mutate(std::vector<uint8_t> b, std::mt19937& rng) {
    auto pick = [&](size_t n) { return n ? size_t(rng() % n) : size_t(0); };
    const int ops = 1 + int(rng() % 4);
    for (int k = 0; k < ops && !b.empty(); ++k) {
        switch (rng() % 7) {
        case 0: b[pick(b.size())] ^= uint8_t(1u << (rng() % 8)); break;
        case 1: {
            static const uint8_t values[] = {0x00, 0xFF, 0x7F, 0x80, 0x7C, 0xFC, 0x01};
            b[pick(b.size())] = values[rng() % 7];
            break;
        }
        case 2: b.resize(pick(b.size())); break;
        case 3: { // a huge or boundary value at an aligned position (counts, offsets, sizes)
            static const uint64_t values[] = {0, 1, 0xFFFFFFFFull, 0x7FFFFFFFull, 0xFFFFFFFFFFFFFFFFull,
                                              uint64_t(1) << 40, 0x7FC00000ull /* NaN bits */};
            const size_t at = pick(b.size() / 4) * 4;
            const uint64_t v = values[rng() % 7];
            const size_t n = std::min<size_t>((rng() & 1) ? 8 : 4, b.size() - at);
            std::memcpy(b.data() + at, &v, n);
            break;
        }
        case 4: { // erase a chunk
            const size_t at = pick(b.size()), n = std::min<size_t>(1 + pick(64), b.size() - at);
            b.erase(b.begin() + long(at), b.begin() + long(at + n));
            break;
        }
        case 5: { // duplicate a chunk
            const size_t at = pick(b.size()), n = std::min<size_t>(1 + pick(64), b.size() - at);
            std::vector<uint8_t> chunk(b.begin() + long(at), b.begin() + long(at + n));
            b.insert(b.begin() + long(pick(b.size())), chunk.begin(), chunk.end());
            break;
        }
        default: b[pick(b.size())] = uint8_t(rng()); break;
        }
    }
    // Most mutants get valid checksums so the structural checks behind them are exercised.
    if (b.size() >= nbvh::model_io::HEADER_BYTES && rng() % 10 < 7) nbvh::test::refresh_checksums(b);
    return b;
}

} // namespace

int main(int argc, char** argv) {
    // `--write-tiny PATH`: save the tiny test model (fixture of the `nbvh info` CLI tests).
    if (argc == 3 && std::string(argv[1]) == "--write-tiny") {
        nbvh::save_model(argv[2], nbvh::test::make_tiny_model());
        return 0;
    }
    const int iterations = argc > 1 ? std::atoi(argv[1]) : 3000;
    const std::vector<uint8_t> model = nbvh::serialize_model(nbvh::test::make_tiny_model());
    nbvh::NeuralModel rich = nbvh::test::make_tiny_model(); // with the optional sections OCCU, MATL and MFIT
    rich.occupancy.assign(rich.nodes.size() * NB_OCC_WORDS, 0x0F0F0F0Fu);
    rich.node_materials.assign(rich.nodes.size(), nb_pack_node_material(0.5f, 0.25f));
    rich.material_fits.assign(rich.nodes.size() * NB_NODE_FIT_WORDS, 0xBC003800u); // fp16 0.5 and -1.0
    const std::vector<uint8_t> rich_bytes = nbvh::serialize_model(rich);
    std::vector<uint8_t> official(16 + 3 * 40 + 8, 0);
    const uint64_t three = 3, one = 1, left = 1, none = 0xFFFFFFFFull, leaf_code = 2;
    std::memcpy(official.data(), &three, 8);
    std::memcpy(official.data() + 8, &one, 8);
    std::memcpy(official.data() + 16 + 24, &left, 8);
    for (int n = 1; n < 3; ++n) {
        std::memcpy(official.data() + 16 + 40 * n + 24, &none, 8);
        std::memcpy(official.data() + 16 + 40 * n + 32, &leaf_code, 8);
    }
    std::mt19937 rng(20240516);
    int accepted = 0;
    for (int i = 0; i < iterations; ++i) {
        const std::vector<uint8_t> m = mutate((i % 5 == 4) ? official : (i % 5 == 3) ? rich_bytes : model, rng);
        LLVMFuzzerTestOneInput(m.data(), m.size());
        try {
            (void)nbvh::parse_model(m, "count");
            accepted++;
        } catch (const nbvh::Error&) {
        }
    }
    // The unmutated inputs must load (else the run proves nothing).
    (void)nbvh::parse_model(model, "seed");
    (void)nbvh::parse_model(rich_bytes, "seed");
    (void)nbvh::import_official_tree(official, "seed");
    std::printf("fuzz_model_reader: %d mutants, %d accepted (all others rejected with nbvh::Error)\n", iterations,
                accepted);
    return 0;
}
#endif
