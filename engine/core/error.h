// The two kinds of error (CONVENTIONS.md "Errors and lifetime"):
//  - nbvh::Error: a user or input error (missing file, bad glTF, corrupt model, unsupported device).
//    Thrown, caught in main, printed as one line, non-zero exit.
//  - NBVH_CHECK / NBVH_ASSERT: a broken invariant. Always on (also in release); aborts with file, line
//    and expression.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace nbvh {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& what) : std::runtime_error(what) {}
};

[[noreturn]] inline void fail_invariant(const char* file, int line, const char* expr, const char* detail) {
    std::fprintf(stderr, "nbvh: internal error at %s:%d: %s%s%s\n", file, line, expr, detail ? ": " : "",
                 detail ? detail : "");
    std::fflush(stderr);
    std::abort();
}

} // namespace nbvh

// Broken invariant: abort with location. Never compiled out.
#define NBVH_CHECK(expr)                                                                          \
    do {                                                                                          \
        if (!(expr)) ::nbvh::fail_invariant(__FILE__, __LINE__, #expr, nullptr);                  \
    } while (0)
#define NBVH_CHECK_MSG(expr, msg)                                                                 \
    do {                                                                                          \
        if (!(expr)) ::nbvh::fail_invariant(__FILE__, __LINE__, #expr, (msg));                    \
    } while (0)
