// The official split schedule's node counts (reference notes §7) and the scheduler's step semantics.
#include <gtest/gtest.h>

#include "engine/core/error.h"
#include "trainer/split_scheduler.h"

namespace nbvh {
namespace {

SplitSchedule make(uint32_t interval, float scaling, uint32_t last = 3000) {
    SplitSchedule s;
    s.splitting_interval = interval;
    s.split_scaling = scaling;
    s.last_split_iteration = last;
    return s;
}

TEST(SplitScheduler, ChessScheduleGives25249Nodes) {
    const ScheduleSimulation sim = simulate_split_schedule(SplitSchedule::chess());
    EXPECT_EQ(sim.nodes, 25249u);
    EXPECT_EQ(sim.splits, 12624u);
    EXPECT_EQ(sim.split_events, 76u);
    EXPECT_EQ(sim.last_split_step, 3000u);
}

TEST(SplitScheduler, CodeDefaultGives2395Nodes) {
    EXPECT_EQ(simulate_split_schedule(SplitSchedule{}).nodes, 2395u);
}

TEST(SplitScheduler, OtherOfficialConfigs) {
    // Reference notes §7 (Chess configs, last split 3000): these file names do not state the real counts.
    EXPECT_EQ(simulate_split_schedule(make(50, 2.3f)).nodes, 7771u);   // "nodes_10903"
    EXPECT_EQ(simulate_split_schedule(make(50, 3.2f)).nodes, 61619u);  // "nodes_72814"
    // ...and these match their names.
    EXPECT_EQ(simulate_split_schedule(make(100, 2.0f)).nodes, 1243u);
    EXPECT_EQ(simulate_split_schedule(make(90, 5.0f)).nodes, 141511u);
    EXPECT_EQ(simulate_split_schedule(make(300, 2.0f)).nodes, 155u);
    EXPECT_EQ(simulate_split_schedule(make(3000, 2.0f)).nodes, 7u);
    // Float arithmetic as in the official int *= float (double products of 2.3f would give 3507).
    EXPECT_EQ(simulate_split_schedule(make(50, 2.3f, 2000)).nodes, 3571u);
}

TEST(SplitScheduler, ChessPerStepCounts) {
    SplitScheduler s(SplitSchedule::chess());
    // 1 at 0, 2 at 40-80, 5 at 120-160, 12 at 200-320, 30 at 360-640, 75 at 680-1280, 187 at 1320-2560,
    // 467 at 2600-3000 (notes §7).
    EXPECT_EQ(s.splits_at(0), 1u);
    EXPECT_EQ(s.splits_at(1), 0u);
    EXPECT_EQ(s.splits_at(39), 0u);
    EXPECT_EQ(s.splits_at(40), 2u);
    EXPECT_EQ(s.splits_at(80), 2u);
    EXPECT_EQ(s.splits_at(120), 5u);
    EXPECT_EQ(s.splits_at(160), 5u);
    EXPECT_EQ(s.splits_at(200), 12u);
    EXPECT_EQ(s.splits_at(320), 12u);
    EXPECT_EQ(s.splits_at(360), 30u);
    EXPECT_EQ(s.splits_at(640), 30u);
    EXPECT_EQ(s.splits_at(680), 75u);
    EXPECT_EQ(s.splits_at(1280), 75u);
    EXPECT_EQ(s.splits_at(1320), 187u);
    EXPECT_EQ(s.splits_at(2560), 187u);
    EXPECT_EQ(s.splits_at(2600), 467u);
    EXPECT_EQ(s.splits_at(3000), 467u);
    EXPECT_EQ(s.splits_at(3040), 0u); // frozen: final training stage
    EXPECT_TRUE(s.frozen_after(3000));
    EXPECT_FALSE(s.frozen_after(2999));
}

TEST(SplitScheduler, AnswersDoNotDependOnWhichStepsWereAsked) {
    SplitScheduler every(SplitSchedule::chess()), sparse(SplitSchedule::chess());
    for (uint32_t i = 0; i <= 3000; ++i) {
        const uint32_t a = every.splits_at(i);
        if (i % 440 == 0) {
            EXPECT_EQ(sparse.splits_at(i), a) << "step " << i;
        }
    }
    // Going back restarts the simulation.
    EXPECT_EQ(every.splits_at(40), 2u);
    EXPECT_EQ(every.splits_at(0), 1u);
}

TEST(SplitScheduler, LodRegistrationEqualIterations) {
    const SplitSchedule s = SplitSchedule::chess(); // last split 3000
    EXPECT_FALSE(lod_registration_due(s, 999, 0, 3));
    EXPECT_TRUE(lod_registration_due(s, 1000, 0, 3));
    EXPECT_FALSE(lod_registration_due(s, 1999, 1, 3));
    EXPECT_TRUE(lod_registration_due(s, 2000, 1, 3));
    EXPECT_TRUE(lod_registration_due(s, 3000, 2, 3));
    EXPECT_FALSE(lod_registration_due(s, 5000, 3, 3)); // all registered
    EXPECT_TRUE(lod_registration_due(s, 3000, 0, 1));
    EXPECT_FALSE(lod_registration_due(s, 2999, 0, 1));
}

TEST(SplitScheduler, RejectsBadParameters) {
    EXPECT_THROW(SplitScheduler(make(0, 2.0f)), Error);
    EXPECT_THROW(SplitScheduler(make(40, 0.5f)), Error);
    EXPECT_THROW(SplitScheduler(make(40, std::numeric_limits<float>::quiet_NaN())), Error);
    SplitSchedule s;
    s.split_interval_scaling = std::numeric_limits<float>::infinity();
    EXPECT_THROW(SplitScheduler{s}, Error);
}

TEST(SplitScheduler, HugeScalingStaysBounded) {
    const ScheduleSimulation sim = simulate_split_schedule(make(1, 1000.0f, 100));
    // The cap (at most the leaf count per event) doubles the tree at most each event.
    EXPECT_GT(sim.nodes, 1u);
    EXPECT_EQ(sim.nodes, 2 * sim.splits + 1);
}

} // namespace
} // namespace nbvh
