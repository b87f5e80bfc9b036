// The bound on missed presentations (runner/src/session/missed_bound.h;
// issue 41): the per-session limit ceil(f × N) against hand-worked values
// (0.1 × 30 is 3.0000000000000004 in binary and must allow 3, not 4), a
// presentation on time resets the consecutive count, repeat_missed = false
// bounds nothing, and the stop record holds the counts added.
#include "session/missed_bound.h"

#include <gtest/gtest.h>

#include "atonlab/store/json.h"

namespace atonlab::runner {
namespace {

protocols::Timing timing(int in_a_row, double fraction, bool repeat = true) {
    protocols::Timing t;
    t.repeat_missed = repeat;
    t.max_missed_in_a_row = in_a_row;
    t.max_missed_fraction = fraction;
    return t;
}

TEST(MissedBound, PerSessionLimitIsTheCeilingOfTheShareAtLeastOne) {
    EXPECT_EQ(MissedBound(timing(5, 0.1), 30, 1.0 / 60).per_session_limit(), 3);  // not 4
    EXPECT_EQ(MissedBound(timing(5, 0.1), 31, 1.0 / 60).per_session_limit(), 4);  // 3.1 → 4
    EXPECT_EQ(MissedBound(timing(5, 0.1), 4, 1.0 / 60).per_session_limit(), 1);   // 0.4 → 1
    EXPECT_EQ(MissedBound(timing(5, 0.25), 80, 1.0 / 60).per_session_limit(), 20);
    EXPECT_EQ(MissedBound(timing(5, 1.0), 4, 1.0 / 60).per_session_limit(), 4);
    EXPECT_FALSE(MissedBound(timing(5, 0.1), std::nullopt, 1.0 / 60).per_session_limit().has_value());
}

TEST(MissedBound, ConsecutiveMissesStopAtTheBoundAndAnOnTimeOneResetsThem) {
    MissedBound b(timing(3, 1.0), std::nullopt, 1.0 / 60);  // no schedule bound: only the consecutive one
    b.add(true, 2);
    b.add(true, 2);
    b.add(false, 0);  // on time: the run of misses starts again
    b.add(true, 4);
    b.add(true, 1);
    EXPECT_FALSE(b.reached());
    b.add(true, 3);
    ASSERT_TRUE(b.reached());
    EXPECT_STREQ(b.reason(), "missed_in_a_row");
    const nlohmann::json r = store::parse_json(b.record(6, ""));
    EXPECT_EQ(r.at("presented_this_run"), 6);
    EXPECT_EQ(r.at("missed_this_run"), 5);
    EXPECT_EQ(r.at("missed_in_a_row"), 3);
    EXPECT_EQ(r.at("dropped_frames"), 2 + 2 + 4 + 1 + 3);
    EXPECT_EQ(r.at("worst_dropped_frames"), 4);
    EXPECT_TRUE(r.at("max_missed_this_run").is_null());
    EXPECT_TRUE(r.at("presentation_margin").is_null());
}

TEST(MissedBound, MoreMissesThanTheShareStopTheRun) {
    MissedBound b(timing(5, 0.1), 30, 1.0 / 60);  // 3 allowed
    for (int i = 0; i < 3; ++i) {
        b.add(true, 1);
        b.add(false, 0);
    }
    EXPECT_FALSE(b.reached()) << "3 missed of 3 allowed";
    b.add(true, 1);
    ASSERT_TRUE(b.reached());
    EXPECT_STREQ(b.reason(), "missed_per_session");
    const std::string m = b.message(12);
    EXPECT_NE(m.find("4 of this run's 7 presentations"), std::string::npos) << m;
    EXPECT_NE(m.find("--resume 12"), std::string::npos) << m;
}

TEST(MissedBound, WithoutRepeatMissedNothingIsBounded) {
    MissedBound b(timing(1, 0.1, false), 4, 1.0 / 60);
    for (int i = 0; i < 10; ++i) b.add(true, 6);
    EXPECT_FALSE(b.reached());
}

}  // namespace
}  // namespace atonlab::runner
