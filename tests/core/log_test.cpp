#include <gtest/gtest.h>

#include "engine/core/log.h"

TEST(Log, StrfmtFormatsAndWarningsAreCounted) {
    EXPECT_EQ(nbvh::strfmt("%d-%s", 42, "x"), "42-x");
    nbvh::set_log_level(nbvh::LogLevel::quiet);
    const int before = nbvh::warning_count();
    nbvh::log_warn("counted %d", 1);
    EXPECT_EQ(nbvh::warning_count(), before + 1);
    nbvh::set_log_level(nbvh::LogLevel::info);
}
