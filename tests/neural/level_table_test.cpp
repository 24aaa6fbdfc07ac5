// Level table, hash and index values pinned against hand-computed ones (official notes §2 tables).
#include <gtest/gtest.h>

#include "engine/core/error.h"
#include "engine/neural/level_table.h"
#include "shaders/shared/mlp.h"

using namespace nbvh;
using namespace nbvh::neural;

namespace {
NeuralConfig config_with_hash(uint32_t log2_hash) {
    NeuralConfig c;
    c.log2_hash_size = log2_hash;
    return c;
}
} // namespace

TEST(LevelTable, PaperDefaultsT18) {
    const auto lv = make_level_table(config_with_hash(18));
    ASSERT_EQ(lv.size(), 8u);
    const uint32_t offsets[8] = {0, 512, 4608, 37376, 299520, 561664, 823808, 1085952};
    const uint32_t sizes[8] = {512, 4096, 32768, 262144, 262144, 262144, 262144, 262144};
    const uint32_t hashed[8] = {0, 0, 0, 0, 1, 1, 1, 1}; // level 3: 64^3 == 2^18 is still dense
    for (uint32_t l = 0; l < 8; ++l) {
        EXPECT_EQ(lv[l].offset, offsets[l]) << l;
        EXPECT_EQ(lv[l].size, sizes[l]) << l;
        EXPECT_EQ(lv[l].resolution, 8u << l) << l;
        EXPECT_EQ(lv[l].scale, float((8u << l) - 1u)) << l; // 7, 15, ..., 1023 exactly
        EXPECT_EQ(lv[l].hashed, hashed[l]) << l;
    }
    EXPECT_EQ(level_table_entries(lv), 1348096u);
    EXPECT_NO_THROW(validate_level_table(lv));
}

TEST(LevelTable, SmallHashT14) {
    const auto lv = make_level_table(config_with_hash(14));
    const uint32_t offsets[8] = {0, 512, 4608, 20992, 37376, 53760, 70144, 86528};
    const uint32_t hashed[8] = {0, 0, 1, 1, 1, 1, 1, 1};
    for (uint32_t l = 0; l < 8; ++l) {
        EXPECT_EQ(lv[l].offset, offsets[l]) << l;
        EXPECT_EQ(lv[l].hashed, hashed[l]) << l;
    }
    EXPECT_EQ(level_table_entries(lv), 102912u);
}

TEST(LevelTable, ParameterCountsMatchOfficialTable) {
    // grid entries x 4 + 19,456 MLP weights (official notes §2).
    EXPECT_EQ(level_table_entries(make_level_table(config_with_hash(16))), 365056u);
    EXPECT_EQ(level_table_entries(make_level_table(config_with_hash(20))), 4493824u);
    EXPECT_EQ(level_table_entries(make_level_table(config_with_hash(22))), 14979584u);
}

TEST(LevelTable, NonPowerOfTwoScaleRoundsDenseSizeToMultipleOf8) {
    NeuralConfig c;
    c.base_resolution = 5; // scale 4 -> res 5 -> 125 vertices -> 128 entries, dense
    c.per_level_scale = 1.5f;
    const auto lv = make_level_table(c);
    EXPECT_EQ(lv[0].resolution, 5u);
    EXPECT_EQ(lv[0].size, 128u);
    EXPECT_EQ(lv[0].hashed, 0u);
    EXPECT_EQ(lv[1].scale, grid_scale(1, 1.5f, 5)); // 6.5
    EXPECT_EQ(lv[1].resolution, 8u);                // ceil(6.5) + 1
    EXPECT_NO_THROW(validate_level_table(lv));
}

TEST(LevelTable, RejectsBadConfigAndCorruptTables) {
    NeuralConfig c;
    c.log2_hash_size = 40;
    EXPECT_THROW(make_level_table(c), Error);
    c = NeuralConfig{};
    c.per_level_scale = std::nanf("");
    EXPECT_THROW(make_level_table(c), Error);
    c = NeuralConfig{};
    c.grid_levels = 9;
    EXPECT_THROW(make_level_table(c), Error);

    auto lv = make_level_table(NeuralConfig{});
    auto bad = lv;
    bad[2].offset += 8;
    EXPECT_THROW(validate_level_table(bad), Error);
    bad = lv;
    bad[5].hashed = 0;
    EXPECT_THROW(validate_level_table(bad), Error);
    bad = lv;
    bad[1].scale = std::numeric_limits<float>::infinity();
    EXPECT_THROW(validate_level_table(bad), Error);
    bad = lv;
    bad.pop_back();
    EXPECT_THROW(validate_level_table(bad), Error);
}

TEST(HashGrid, CoherentPrimeByHand) {
    EXPECT_EQ(nb_hash_coherent_prime(0, 0, 0), 0u);
    EXPECT_EQ(nb_hash_coherent_prime(1, 0, 0), 1u);
    EXPECT_EQ(nb_hash_coherent_prime(0, 1, 0), 2654435761u);
    EXPECT_EQ(nb_hash_coherent_prime(0, 0, 1), 805459861u);
    // 1 ^ 2654435761 ^ 805459861 = 2922720805
    EXPECT_EQ(nb_hash_coherent_prime(1, 1, 1), 2922720805u);
    // wrapping multiplies: 17*2654435761 mod 2^32 = 2175734977, 3*805459861 = 2416379583; 5 ^ both
    EXPECT_EQ(nb_hash_coherent_prime(5, 17, 3), 296227451u);
    const auto lv = make_level_table(NeuralConfig{});
    // level 4 (hashed, 2^18): index = hash mod 2^18. (0,1,0): 2654435761 - 10125 * 2^18 = 227761.
    EXPECT_EQ(nb_grid_vertex_index(lv[4], 0, 1, 0), 227761u);
    EXPECT_EQ(nb_grid_vertex_index(lv[4], 1, 1, 1), 77349u);
    EXPECT_EQ(nb_grid_vertex_index(lv[7], 127, 128, 128), 201343u);
    // a wrapped (negative) cell: 0xFFFFFFFF mod 2^18
    EXPECT_EQ(nb_grid_vertex_index(lv[7], 0xFFFFFFFFu, 0, 0), 262143u);
}

TEST(HashGrid, DenseIndexAndTcnnAliasing) {
    const auto lv = make_level_table(NeuralConfig{});
    // level 0: res 8, 512 entries: x + 8y + 64z
    EXPECT_EQ(nb_grid_vertex_index(lv[0], 3, 2, 1), 3u + 16u + 64u);
    // x == res aliases into the next row: (8, 0, 0) reads (0, 1, 0)
    EXPECT_EQ(nb_grid_vertex_index(lv[0], 8, 0, 0), nb_grid_vertex_index(lv[0], 0, 1, 0));
    // the last slab wraps: (7, 7, 8) -> 575 % 512 = 63 = (7, 7, 0)
    EXPECT_EQ(nb_grid_vertex_index(lv[0], 7, 7, 8), 63u);
    // x = 1.0 at level 0: pos = 7.5 -> cell 7, frac 0.5; corner 1 is x = 8 (aliased)
    uvec3 cell;
    vec3 frac;
    nb_grid_position(lv[0], vec3(1.0f, 0.0f, 0.0f), cell, frac);
    EXPECT_EQ(cell.x, 7u);
    EXPECT_EQ(cell.y, 0u);
    EXPECT_FLOAT_EQ(frac.x, 0.5f);
    EXPECT_FLOAT_EQ(frac.y, 0.5f);
    EXPECT_EQ(nb_grid_corner_index(lv[0], cell, 1u), 8u);
    EXPECT_EQ(nb_grid_corner_entry(lv[1], uvec3(0, 0, 0), 7u), 512u + 1u + 16u + 256u);
    // level 3 is dense with res^3 == size: (63, 63, 64) wraps to (63, 63, 0)
    EXPECT_EQ(nb_grid_vertex_index(lv[3], 63, 63, 64), 63u + 63u * 64u);
}

// The index takes `& (size - 1)` for power-of-two sizes instead of `% size`: the same value for every
// vertex, on every level of tables with dense and hashed, power-of-two and other sizes (hashgrid.h).
TEST(HashGrid, PowerOfTwoShortcutEqualsTheModulo) {
    uint32_t state = 12345u;
    auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return state;
    };
    int pow2 = 0, other = 0;
    for (uint32_t log2_hash : {4u, 13u, 17u, 18u, 22u}) {
        for (uint32_t base : {2u, 7u, 16u, 100u}) {
            NeuralConfig cfg;
            cfg.log2_hash_size = log2_hash;
            cfg.base_resolution = base;
            for (const GpuHashLevel& lv : make_level_table(cfg)) {
                ((lv.size & (lv.size - 1u)) == 0u ? pow2 : other)++;
                const uint32_t r = lv.resolution;
                const uint32_t edge[] = {0u, 1u, r - 1u, r, r + 1u, 0x7FFFFFFFu, 0xFFFFFFFEu, 0xFFFFFFFFu};
                for (int k = 0; k < 300; ++k) {
                    const uint32_t x = k < 64 ? edge[k % 8] : next(),
                                   y = k < 64 ? edge[(k / 8) % 8] : next() % (r + 2u), z = next();
                    const uint32_t idx = lv.hashed
                                             ? nb_hash_coherent_prime(x, y, z)
                                             : x + y * lv.resolution + z * (lv.resolution * lv.resolution);
                    ASSERT_EQ(nb_grid_vertex_index(lv, x, y, z), idx % lv.size)
                        << "size " << lv.size << " at " << x << ", " << y << ", " << z;
                }
            }
        }
    }
    EXPECT_GT(pow2, 0);
    EXPECT_GT(other, 0); // both branches taken
}

TEST(HashGrid, PositionWeightsAndSlots) {
    const auto lv = make_level_table(NeuralConfig{});
    uvec3 cell;
    vec3 frac;
    // level 2 (scale 31): 0.25 * 31 + 0.5 = 8.25 -> cell 8, frac 0.25
    nb_grid_position(lv[2], vec3(0.25f, 0.5f, 0.0f), cell, frac);
    EXPECT_EQ(cell.x, 8u);
    EXPECT_FLOAT_EQ(frac.x, 0.25f);
    EXPECT_EQ(cell.y, 16u); // 15.5 + 0.5
    EXPECT_FLOAT_EQ(frac.y, 0.0f);
    // negative encoded coordinate wraps like tcnn's (uint32_t)(int)floorf
    nb_grid_position(lv[7], vec3(-1e-3f, 0.0f, 0.0f), cell, frac);
    EXPECT_EQ(cell.x, 0xFFFFFFFFu); // 1023 * -1e-3 + 0.5 = -0.523 -> -1
    float sum = 0.0f;
    const vec3 f(0.3f, 0.6f, 0.9f);
    for (uint32_t c = 0; c < 8; ++c) sum += nb_grid_corner_weight(f, c);
    EXPECT_NEAR(sum, 1.0f, 1e-6f);
    EXPECT_FLOAT_EQ(nb_grid_corner_weight(f, 0u), 0.7f * 0.4f * 0.1f);
    EXPECT_FLOAT_EQ(nb_grid_corner_weight(f, 5u), 0.3f * 0.4f * 0.9f);
    EXPECT_EQ(nb_feature_slot(0, 0, 0), 0u);
    EXPECT_EQ(nb_feature_slot(1, 2, 3), 32u + 8u + 3u);
    EXPECT_EQ(nb_feature_slot(2, 7, 3), 95u);
}

TEST(Mlp, WeightIndexLayout) {
    EXPECT_EQ(NB_MLP_WEIGHT_COUNT, 19456u);
    EXPECT_EQ(nb_mlp_layer_offset(0), 0u);
    EXPECT_EQ(nb_mlp_layer_offset(1), 6144u);
    EXPECT_EQ(nb_mlp_layer_offset(2), 10240u);
    EXPECT_EQ(nb_mlp_layer_offset(3), 14336u);
    EXPECT_EQ(nb_mlp_layer_offset(4), 18432u);
    EXPECT_EQ(nb_mlp_weight_index(0, 1, 0), 96u);  // row-major out x in
    EXPECT_EQ(nb_mlp_weight_index(4, 15, 63), 19455u);
    EXPECT_EQ(nb_mlp_weight_index(2, 3, 5), 10240u + 3u * 64u + 5u);
    EXPECT_EQ(nb_mlp_layer_outputs(4), 16u);
    EXPECT_EQ(nb_mlp_layer_inputs(0), 96u);
    EXPECT_FLOAT_EQ(nb_sigmoid(0.0f), 0.5f);
    EXPECT_EQ(nb_sigmoid(-200.0f), 0.0f);
    EXPECT_EQ(nb_sigmoid(200.0f), 1.0f);
}

// The render passes read each level packed in one 16-byte word (hashgrid.h nb_level_pack): every field
// they use survives, for dense and hashed levels of several tables; resolutions at bit 31 are refused.
TEST(HashGrid, PackedLevelsRoundTrip) {
    for (uint32_t log2_hash : {4u, 14u, 18u, 24u}) {
        for (uint32_t base : {2u, 16u, 4096u}) {
            NeuralConfig cfg;
            cfg.log2_hash_size = log2_hash;
            cfg.base_resolution = base;
            cfg.per_level_scale = base == 4096u ? 16.0f : 2.0f;
            std::vector<GpuHashLevel> levels;
            try {
                levels = make_level_table(cfg);
            } catch (const Error&) {
                continue; // a table too large for the renderer
            }
            for (const GpuHashLevel& lv : levels) {
                const GpuHashLevel u = nb_level_unpack(nb_level_pack(lv));
                EXPECT_EQ(u.offset, lv.offset);
                EXPECT_EQ(u.size, lv.size);
                EXPECT_EQ(u.resolution, lv.resolution);
                EXPECT_EQ(floatBitsToUint(u.scale), floatBitsToUint(lv.scale));
                EXPECT_EQ(u.hashed, lv.hashed);
            }
        }
    }
    std::vector<GpuHashLevel> bad = make_level_table(NeuralConfig{});
    bad[7].resolution = NB_LEVEL_HASHED_BIT;
    EXPECT_THROW(validate_level_table(bad), Error);
}
