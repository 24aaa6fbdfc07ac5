// Seeds of the model fuzz target, made by the current writer (serialize_model) so they always follow the
// current format: no binary model is committed. Written to a directory by make_model_seeds (scripts/fuzz.sh)
// and replayed in-process by the unit test.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace nbvh::fuzz {

struct Seed {
    std::string name;           // file name; "valid_*" seeds must load
    std::vector<uint8_t> bytes;
};

// A handful of valid models (tests/model/tiny_model.h and variations of it: several assets, another hash
// size, one and four LoDs, a root-only tree, occupancy masks and node materials), truncated and bit-flipped copies of the tiny model (flips with
// the checksums recomputed, so they reach the section decoders), and an official-format tree file.
std::vector<Seed> model_seeds();

} // namespace nbvh::fuzz
