#include <gtest/gtest.h>

#include "engine/core/log.h"

// The one formatter behind Vulkan's and CUDA's UUID text (their equality picks the training GPU).
TEST(Log, UuidIsFormattedLikeNvidiaSmi) {
    const unsigned char u[16] = {0x9d, 0x03, 0x91, 0x23, 0x8d, 0xba, 0x7e, 0xe7,
                                 0x16, 0x38, 0x42, 0xa0, 0x15, 0xd6, 0x60, 0xed};
    EXPECT_EQ(nbvh::format_uuid(u), "9d039123-8dba-7ee7-1638-42a015d660ed"); // nvidia-smi -L on the H200
    const unsigned char zero[16] = {};
    EXPECT_EQ(nbvh::format_uuid(zero), "00000000-0000-0000-0000-000000000000");
}

TEST(Log, StrfmtFormatsAndWarningsAreCounted) {
    EXPECT_EQ(nbvh::strfmt("%d-%s", 42, "x"), "42-x");
    nbvh::set_log_level(nbvh::LogLevel::quiet);
    const int before = nbvh::warning_count();
    nbvh::log_warn("counted %d", 1);
    EXPECT_EQ(nbvh::warning_count(), before + 1);
    nbvh::set_log_level(nbvh::LogLevel::info);
}
