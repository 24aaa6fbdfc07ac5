#include "trainer/progress_bar.h"

#include <chrono>
#include <cmath>
#include <string>

#include <unistd.h>

#include "engine/core/log.h"

namespace nbvh {

std::string format_duration(double s) {
    if (!std::isfinite(s) || s < 0.0) return "?";
    if (s < 60.0) return strfmt("%.1fs", s);
    const long total = long(s + 0.5);
    if (total < 3600) return strfmt("%ldm%02lds", total / 60, total % 60);
    return strfmt("%ldh%02ldm", total / 3600, (total % 3600) / 60);
}

ProgressBar::ProgressBar(FILE* out) : out_(out) { tty_ = out_ && isatty(fileno(out_)); }

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::finish() {
    if (open_line_ && out_) {
        std::fputc('\n', out_);
        std::fflush(out_);
    }
    open_line_ = false;
}

void ProgressBar::update(const TrainProgress& p) {
    if (!out_ || p.steps == 0) return;
    const double now =
        std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    const bool last = p.step >= p.steps;
    const std::string text =
        strfmt("step %u/%u  nodes %u  loss %.4f  %.0f samples/s  ETA %s%s", p.step, p.steps, p.nodes, p.loss,
               p.samples_per_s, format_duration(p.eta_s).c_str(), p.final_stage ? "  (final stage)" : "");
    if (tty_) {
        if (!last && now - last_print_ < 0.2) return;
        last_print_ = now;
        const int width = 24;
        const int filled = int(double(width) * double(p.step) / double(p.steps));
        std::string bar(size_t(filled), '#');
        bar.append(size_t(width - filled), '.');
        std::fprintf(out_, "\r[%s] %s\x1b[K", bar.c_str(), text.c_str());
        open_line_ = true;
        if (last) finish();
        std::fflush(out_);
    } else {
        const uint32_t bucket = uint32_t(uint64_t(p.step) * 20u / p.steps);
        if (bucket == last_bucket_ && !last) return;
        last_bucket_ = bucket;
        std::fprintf(out_, "%s\n", text.c_str());
        std::fflush(out_);
    }
}

} // namespace nbvh
