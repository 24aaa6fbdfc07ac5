// One progress bar over a whole study with an ETA (issue 11). The sweep is planned up front as tasks of
// two kinds: training (work = samples to train) and rendering (work = pixel samples, hybrid renders
// counted 1.5x). Each kind's rate is measured as its tasks finish (training also from the steps of the
// running task), so the ETA = remaining work / measured rate, summed over the kinds. On a terminal the
// bar is one line redrawn in place; otherwise one line per finished task (logs of GPU runs).
#pragma once
#include <cstdio>
#include <string>

namespace nbvh::app {

enum class StudyTask { train = 0, render = 1 };

class StudyProgress {
  public:
    explicit StudyProgress(FILE* out = stderr);
    ~StudyProgress();

    void plan(StudyTask kind, double work); // adds a task to the total
    void begin(StudyTask kind, double work, std::string label);
    void partial(double fraction);            // of the running task (training steps)
    void end(const std::string& result = {}); // the running task is done; `result` is printed beside it
    void note(const std::string& line);       // a line of its own (the bar is redrawn after it)
    double eta_seconds() const;
    double elapsed_seconds() const;

  private:
    void draw(bool force);
    FILE* out_;
    bool tty_ = false, open_line_ = false;
    double t0_ = 0.0, task_t0_ = 0.0, last_draw_ = -1.0;
    double planned_[2] = {0, 0}, done_[2] = {0, 0}, seconds_[2] = {0, 0};
    StudyTask kind_ = StudyTask::render;
    double work_ = 0.0, fraction_ = 0.0;
    int tasks_planned_ = 0, tasks_done_ = 0;
    std::string label_;
};

} // namespace nbvh::app
