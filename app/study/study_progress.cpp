#include "app/study/study_progress.h"

#include <algorithm>
#include <chrono>

#include <unistd.h>

#include "engine/core/log.h"
#include "trainer/progress_bar.h"

namespace nbvh::app {

namespace {
double now_s() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
// Before a kind has a measured rate: the other kind's seconds per unit of work are meaningless, so
// these first guesses (an H100: ~2e7 trained samples/s, ~5e8 pixel samples/s) stand in.
constexpr double DEFAULT_RATE[2] = {2.0e7, 5.0e8};
} // namespace

StudyProgress::StudyProgress(FILE* out) : out_(out) {
    tty_ = out_ && isatty(fileno(out_));
    t0_ = now_s();
}

StudyProgress::~StudyProgress() {
    if (open_line_ && out_) std::fputc('\n', out_);
}

void StudyProgress::plan(StudyTask kind, double work) {
    planned_[int(kind)] += work;
    tasks_planned_++;
}

void StudyProgress::begin(StudyTask kind, double work, std::string label) {
    kind_ = kind;
    work_ = work;
    fraction_ = 0.0;
    label_ = std::move(label);
    task_t0_ = now_s();
    draw(true);
}

void StudyProgress::partial(double fraction) {
    fraction_ = std::clamp(fraction, 0.0, 1.0);
    draw(false);
}

void StudyProgress::end(const std::string& result) {
    const int k = int(kind_);
    done_[k] += work_;
    seconds_[k] += now_s() - task_t0_;
    tasks_done_++;
    fraction_ = 0.0;
    work_ = 0.0;
    if (!tty_ && out_) {
        std::fprintf(out_, "[%3.0f%%] %s%s%s  (%s elapsed, ETA %s)\n",
                     100.0 * double(tasks_done_) / double(std::max(1, tasks_planned_)), label_.c_str(),
                     result.empty() ? "" : ": ", result.c_str(), format_duration(elapsed_seconds()).c_str(),
                     format_duration(eta_seconds()).c_str());
        std::fflush(out_);
    } else if (!result.empty()) {
        note(label_ + ": " + result);
    }
    label_.clear();
    draw(true);
}

void StudyProgress::note(const std::string& line) {
    if (!out_) return;
    if (open_line_) std::fprintf(out_, "\r\x1b[K");
    std::fprintf(out_, "%s\n", line.c_str());
    open_line_ = false;
    std::fflush(out_);
    draw(true);
}

double StudyProgress::elapsed_seconds() const { return now_s() - t0_; }

double StudyProgress::eta_seconds() const {
    double eta = 0.0;
    for (int k = 0; k < 2; ++k) {
        double done = done_[k], secs = seconds_[k];
        if (k == int(kind_) && work_ > 0.0 && fraction_ > 0.0) { // the running task's part
            done += work_ * fraction_;
            secs += now_s() - task_t0_;
        }
        const double rate = done > 0.0 && secs > 0.0 ? done / secs : DEFAULT_RATE[k];
        const double running = k == int(kind_) ? work_ * fraction_ : 0.0;
        eta += std::max(0.0, planned_[k] - done_[k] - running) / rate;
    }
    return eta;
}

void StudyProgress::draw(bool force) {
    if (!tty_ || !out_) return;
    const double t = now_s();
    if (!force && t - last_draw_ < 0.2) return;
    last_draw_ = t;
    double total = 0.0, done = 0.0;
    for (int k = 0; k < 2; ++k) { // progress in estimated seconds, so training and rendering weigh by time
        const double rate = done_[k] > 0.0 && seconds_[k] > 0.0 ? done_[k] / seconds_[k] : DEFAULT_RATE[k];
        total += planned_[k] / rate;
        done += (done_[k] + (k == int(kind_) ? work_ * fraction_ : 0.0)) / rate;
    }
    const double f = total > 0.0 ? std::clamp(done / total, 0.0, 1.0) : 0.0;
    const int width = 24, filled = int(width * f);
    std::string bar(size_t(filled), '#');
    bar.append(size_t(width - filled), '.');
    std::fprintf(out_, "\r[%s] %3.0f%%  %d/%d  %s  ETA %s\x1b[K", bar.c_str(), 100.0 * f, tasks_done_,
                 tasks_planned_, label_.c_str(), format_duration(eta_seconds()).c_str());
    open_line_ = true;
    std::fflush(out_);
}

} // namespace nbvh::app
