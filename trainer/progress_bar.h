// Training progress on stderr: one line updated in place with \r on a terminal, plain lines (about
// every 5 % of the run) when stderr is redirected, so logs stay readable.
#pragma once
#include <cstdio>

#include "trainer/trainer.h"

namespace nbvh {

class ProgressBar {
public:
    explicit ProgressBar(FILE* out = stderr);
    ~ProgressBar(); // finishes the line
    void update(const TrainProgress& p);
    void finish();

private:
    FILE* out_;
    bool tty_ = false;
    bool open_line_ = false;
    double last_print_ = -1.0;
    uint32_t last_bucket_ = ~0u;
};

// "1m23s", "45.2s".
std::string format_duration(double seconds);

} // namespace nbvh
