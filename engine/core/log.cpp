#include "engine/core/log.h"

#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <vector>

namespace nbvh {
namespace {
std::atomic<int> g_level{static_cast<int>(LogLevel::info)};
std::atomic<int> g_warnings{0};

void emit(LogLevel level, const char* prefix, const char* fmt, va_list args) {
    if (static_cast<int>(level) < g_level.load()) return;
    char buffer[2048];
    std::vsnprintf(buffer, sizeof buffer, fmt, args);
    std::fprintf(stderr, "%s%s\n", prefix, buffer);
}
} // namespace

void set_log_level(LogLevel level) { g_level = static_cast<int>(level); }
LogLevel log_level() { return static_cast<LogLevel>(g_level.load()); }
int warning_count() { return g_warnings.load(); }
void reset_warning_count() { g_warnings = 0; }

#define NBVH_LOG_FN(name, level, prefix)                                                          \
    void name(const char* fmt, ...) {                                                             \
        va_list args;                                                                             \
        va_start(args, fmt);                                                                      \
        emit(level, prefix, fmt, args);                                                           \
        va_end(args);                                                                             \
    }
NBVH_LOG_FN(log_debug, LogLevel::debug, "debug: ")
NBVH_LOG_FN(log_info, LogLevel::info, "")
NBVH_LOG_FN(log_error, LogLevel::error, "error: ")
#undef NBVH_LOG_FN

void log_warn(const char* fmt, ...) {
    ++g_warnings;
    va_list args;
    va_start(args, fmt);
    emit(LogLevel::warn, "warning: ", fmt, args);
    va_end(args);
}

std::string strfmt(const char* fmt, ...) {
    va_list args, copy;
    va_start(args, fmt);
    va_copy(copy, args);
    const int n = std::vsnprintf(nullptr, 0, fmt, copy);
    va_end(copy);
    std::string out(n > 0 ? size_t(n) : 0, '\0');
    if (n > 0) std::vsnprintf(out.data(), out.size() + 1, fmt, args);
    va_end(args);
    return out;
}

std::string format_uuid(const unsigned char* bytes16) {
    std::string s;
    for (int i = 0; i < 16; ++i) {
        if (i == 4 || i == 6 || i == 8 || i == 10) s += '-';
        s += strfmt("%02x", unsigned(bytes16[i]));
    }
    return s;
}

} // namespace nbvh
