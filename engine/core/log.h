// Minimal leveled logging to stderr (printf-style: g++ 12 has no <format>). Warnings are counted so
// tests can assert that a bad input warned.
#pragma once
#include <string>

namespace nbvh {

enum class LogLevel { debug = 0, info = 1, warn = 2, error = 3, quiet = 4 };

void set_log_level(LogLevel level);
LogLevel log_level();
int warning_count(); // warnings emitted since start or since reset_warning_count()
void reset_warning_count();

void log_debug(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
void log_info(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
void log_warn(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
void log_error(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

// printf into a std::string (for building Error messages).
std::string strfmt(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

// A 16-byte UUID as 8-4-4-4-12 lower-case hex digits, the form nvidia-smi prints after "GPU-": Vulkan's
// deviceUUID and CUDA's cudaDeviceProp::uuid of one GPU give the same text (how `nbvh study --device
// gpu:N` trains on the GPU it renders on).
std::string format_uuid(const unsigned char* bytes16);

} // namespace nbvh
