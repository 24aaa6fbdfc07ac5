// The exponential split schedule of the tree-cut optimisation (paper §3.2 "Base-BVH cut optimization";
// official notes §7, BvhSplitScheduler). Splits happen only at steps i <= last_split_iteration with
// i % splitting_interval == 0; each such step splits `cur` leaves. Whenever i % cur_interval == 0 (after
// the split of that step), cur = trunc(cur * split_scaling) and cur_interval = trunc(cur_interval *
// split_interval_scaling). cur starts at start_split_num, cur_interval at splitting_interval.
// Chess (40, 3000, 1, 2.5, 2.0) gives 76 split events, 12,624 splits, 25,249 nodes; the code defaults
// (50, 2000, 1, 2.0, 2.0) give 2,395 nodes.
//
// Order within one training step i (the trainer's contract): optimiser step, then split splits_at(i)
// leaves, then register a level of detail if lod_registration_due(i, ...) says so.
#pragma once
#include <cstdint>
#include <string>

namespace nbvh {

struct SplitSchedule {
    uint32_t splitting_interval = 50;
    uint32_t last_split_iteration = 2000;
    uint32_t start_split_num = 1;
    float split_scaling = 2.0f;
    float split_interval_scaling = 2.0f;

    static SplitSchedule chess() { return {40, 3000, 1, 2.5f, 2.0f}; } // the shipped "nodes_32940" config
};

// Throws nbvh::Error naming the bad field (zero interval, scaling < 1 or non-finite, ...).
void validate(const SplitSchedule& schedule);

// Stateful: call with non-decreasing steps (a smaller step restarts the simulation from 0, like the
// official reset at step 0). Steps that are skipped are simulated, so the answer never depends on
// which steps the caller asked about.
class SplitScheduler {
public:
    explicit SplitScheduler(const SplitSchedule& schedule);
    const SplitSchedule& schedule() const { return schedule_; }
    // Number of leaves to split after the optimiser step of training step `step` (0 = none).
    uint32_t splits_at(uint32_t step);
    // True once no step >= `step` can split any more (the cut is frozen: final training stage).
    bool frozen_after(uint32_t step) const { return step >= schedule_.last_split_iteration; }

private:
    void restart();
    SplitSchedule schedule_;
    uint64_t next_step_ = 0;      // next step to be simulated
    uint64_t cur_splits_ = 0;     // splits per split event now
    uint64_t cur_interval_ = 0;   // steps until the next growth of cur_splits_
};

// EqualIterations rule (official §7): with `lod_count` cuts to learn, LoD number `registered` (counted
// from the coarsest, 0-based) is registered at step (registered + 1) * last_split_iteration / lod_count,
// and every remaining one is registered (one per call) once step >= last_split_iteration.
bool lod_registration_due(const SplitSchedule& schedule, uint32_t step, uint32_t registered, uint32_t lod_count);

// What the schedule produces on a base BVH deep enough never to run out of splittable leaves, with
// the official cap of at most (nodes + 1) / 2 splits per event (the number of leaves of the cut).
// Node counts saturate at 2^50.
struct ScheduleSimulation {
    uint64_t nodes = 1;        // final N-BVH node count (start: the root alone)
    uint64_t splits = 0;       // total leaves split
    uint32_t split_events = 0; // steps at which at least one leaf was split
    uint32_t last_split_step = 0;
};
ScheduleSimulation simulate_split_schedule(const SplitSchedule& schedule, uint64_t start_nodes = 1);

std::string describe(const SplitSchedule& schedule); // "interval 40, last 3000, start 1, scaling 2.5 x2"

} // namespace nbvh
