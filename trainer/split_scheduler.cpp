#include "trainer/split_scheduler.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh {

namespace {
// Beyond this many splits per event the schedule is meaningless (the cut would exceed any model);
// clamping keeps the integer arithmetic far from overflow for absurd scalings.
constexpr uint64_t MAX_SPLITS_PER_EVENT = uint64_t(1) << 40;
constexpr uint64_t MAX_INTERVAL = uint64_t(1) << 40;
constexpr uint64_t MAX_SIMULATED_NODES = uint64_t(1) << 50;
} // namespace

void validate(const SplitSchedule& s) {
    if (s.splitting_interval == 0) throw Error("split schedule: splitting_interval must be at least 1");
    if (!std::isfinite(s.split_scaling) || s.split_scaling < 1.0f || s.split_scaling > 1000.0f)
        throw Error(strfmt("split schedule: split_scaling %g must be in [1, 1000]", double(s.split_scaling)));
    if (!std::isfinite(s.split_interval_scaling) || s.split_interval_scaling < 1.0f ||
        s.split_interval_scaling > 1000.0f)
        throw Error(strfmt("split schedule: split_interval_scaling %g must be in [1, 1000]",
                           double(s.split_interval_scaling)));
}

SplitScheduler::SplitScheduler(const SplitSchedule& schedule) : schedule_(schedule) {
    validate(schedule_);
    restart();
}

void SplitScheduler::restart() {
    next_step_ = 0;
    cur_splits_ = schedule_.start_split_num;
    cur_interval_ = schedule_.splitting_interval;
}

uint32_t SplitScheduler::splits_at(uint32_t step) {
    if (step < next_step_) restart();
    uint64_t result = 0;
    const uint64_t last = std::min<uint64_t>(step, schedule_.last_split_iteration);
    // Simulate every step up to `step` (at most last_split_iteration + 1 steps in a run in total).
    for (uint64_t i = next_step_; i <= last; ++i) {
        const uint64_t splits = (i % schedule_.splitting_interval == 0) ? cur_splits_ : 0;
        if (i == step) result = splits;
        if (i % cur_interval_ == 0) {
            // The official `int *= float`: a float product, then truncation. Float (not double)
            // matters: 10 * 2.3f rounds to 23.0f, in double it is 22.99999... -> 22.
            const float next_splits = float(cur_splits_) * schedule_.split_scaling;
            const float next_interval = float(cur_interval_) * schedule_.split_interval_scaling;
            cur_splits_ = std::min<uint64_t>(MAX_SPLITS_PER_EVENT, uint64_t(next_splits));
            cur_interval_ = std::clamp<uint64_t>(uint64_t(next_interval), 1, MAX_INTERVAL);
        }
    }
    next_step_ = std::max<uint64_t>(next_step_, last + 1);
    if (step > schedule_.last_split_iteration) next_step_ = uint64_t(step) + 1;
    return uint32_t(std::min<uint64_t>(result, 0xFFFFFFFFu));
}

bool lod_registration_due(const SplitSchedule& s, uint32_t step, uint32_t registered, uint32_t lod_count) {
    if (lod_count == 0 || registered >= lod_count) return false;
    if (step >= s.last_split_iteration) return true;
    const uint64_t due = uint64_t(registered + 1) * s.last_split_iteration / lod_count;
    return due <= step;
}

ScheduleSimulation simulate_split_schedule(const SplitSchedule& schedule, uint64_t start_nodes) {
    SplitScheduler scheduler(schedule);
    ScheduleSimulation sim;
    sim.nodes = std::max<uint64_t>(start_nodes, 1);
    for (uint32_t i = 0; i <= schedule.last_split_iteration; ++i) {
        uint64_t k = scheduler.splits_at(i);
        if (k == 0) continue;
        k = std::min<uint64_t>(k, (sim.nodes + 1) / 2); // official cap: at most the cut's leaf count
        k = std::min<uint64_t>(k, (MAX_SIMULATED_NODES - sim.nodes) / 2); // no overflow for absurd schedules
        if (k == 0) continue;
        sim.splits += k;
        sim.nodes += 2 * k;
        sim.split_events++;
        sim.last_split_step = i;
    }
    return sim;
}

std::string describe(const SplitSchedule& s) {
    return strfmt("interval %u, last split %u, start %u, scaling %g, interval scaling %g", s.splitting_interval,
                  s.last_split_iteration, s.start_split_num, double(s.split_scaling),
                  double(s.split_interval_scaling));
}

} // namespace nbvh
