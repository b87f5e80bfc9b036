// The bound on missed presentations (issue 41; docs/running.md "Missed frames
// and timeouts") on the headless virtual display, where an injected stall of
// N refreshes makes its trial miss with exactly N refreshes dropped:
//  - a stall on every trial stops the run at max_missed_in_a_row, or when its
//    missed presentations exceed max_missed_fraction of the schedule's bound:
//    exit status 7, every stored trial kept, the session `quit` with a stop
//    record (sessions.stop_json) that says what was measured;
//  - --resume-last continues it (each stop appended to the record), and the
//    completed session's counted trials are those of an uninterrupted run;
//  - `atonlab analyze` shows the stops.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "../support/child_process.h"
#include "../support/skip.h"
#include "atonlab/store/json.h"
#include "atonlab/store/store.h"

#ifndef ATONLAB_BINARY
#error "ATONLAB_BINARY (the atonlab executable) must be defined by the build"
#endif

namespace atonlab {
namespace {

namespace fs = std::filesystem;
using store::Store;
using store::TrialRecord;
using store::test_support::file_bytes;
using store::test_support::TempDir;

const fs::path kData = fs::path(ATONLAB_SOURCE_DIR) / "tests/data/runner";

/// screen_stall.toml (4 trials of constant stimuli, repeat_missed = true)
/// with its scene path made absolute and `timing_extra` added to [timing].
fs::path protocol_copy(const TempDir& dir, const std::string& timing_extra) {
    std::string text = file_bytes(kData / "screen_stall.toml");
    text.replace(text.find("\"screen.scene.toml\""), 19, "\"" + (kData / "screen.scene.toml").string() + "\"");
    text.replace(text.find("[timing]\n"), 9, "[timing]\n" + timing_extra + "\n");
    const fs::path p = dir.path() / "p.toml";
    std::ofstream(p) << text;
    return p;
}

const std::vector<std::string> kStallEveryTrial{"--inject-stall-frames", "6", "--inject-stall-every-trial"};

class MissedBound : public ::testing::Test {
protected:
    int run(const fs::path& protocol, const fs::path& db, std::vector<std::string> extra) {
        std::vector<std::string> args{"run",        protocol.string(), "--db",         db.string(),
                                      "--headless", "--no-true-pse",   "--model-observer"};
        args.insert(args.end(), extra.begin(), extra.end());
        const test::Captured r = test::atonlab(std::move(args), dir_.path());
        err_ = r.err;
        out_ = r.out;
        if (r.code == 3) skipped_ = true;
        return r.code;
    }
    store::SessionRecord session(const fs::path& db) { return Store::open_read_only(db).sessions().back(); }
    std::vector<TrialRecord> trials(const fs::path& db) {
        Store s = Store::open_read_only(db);
        return s.trials(s.sessions().back().id);
    }
    TempDir dir_;
    bool skipped_ = false;
    std::string err_, out_;
};

TEST_F(MissedBound, AStallOnEveryTrialStopsAtTheConsecutiveBound) {
    // 3 in a row; a share of 1 allows 4 missed of the 4 trials, so the consecutive bound comes first.
    const fs::path protocol = protocol_copy(dir_, "max_missed_in_a_row = 3\nmax_missed_fraction = 1.0");
    const fs::path db = dir_.path() / "s.db";
    const int status = run(protocol, db, kStallEveryTrial);
    if (skipped_) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << err_;
    ASSERT_EQ(status, 7) << err_;
    const auto t = trials(db);
    ASSERT_EQ(t.size(), 3u) << "stopped at the third missed presentation in a row";
    for (const TrialRecord& r : t) {
        EXPECT_EQ(r.response, "missed");
        EXPECT_TRUE(r.missed_deadline);
        EXPECT_EQ(r.dropped_frames, 6);  // headless the stall loses exactly its 6 refreshes
    }
    const store::SessionRecord s = session(db);
    EXPECT_EQ(s.status, store::SessionStatus::quit);
    ASSERT_TRUE(s.stop_json.has_value());
    const nlohmann::json stops = store::parse_json(*s.stop_json);
    ASSERT_TRUE(stops.is_array());
    ASSERT_EQ(stops.size(), 1u);
    const nlohmann::json& stop = stops[0];
    EXPECT_EQ(stop.at("reason"), "missed_in_a_row");
    EXPECT_EQ(stop.at("trials_stored"), 3);
    EXPECT_EQ(stop.at("missed_in_a_row"), 3);
    EXPECT_EQ(stop.at("max_missed_in_a_row"), 3);
    EXPECT_EQ(stop.at("max_missed_this_run"), 4);  // ceil(1.0 × 4)
    EXPECT_EQ(stop.at("dropped_frames"), 3 * 6);
    EXPECT_EQ(stop.at("worst_dropped_frames"), 6);
    EXPECT_DOUBLE_EQ(stop.at("refresh_period_s").get<double>(), 1.0 / 60.0);
    EXPECT_TRUE(stop.at("presentation_margin").is_null()) << "headless: no margin is measured";
    EXPECT_TRUE(stop.contains("stopped_at"));
    // One message: what was measured and what to do.
    EXPECT_NE(err_.find("3 presentations in a row missed their refresh"), std::string::npos) << err_;
    EXPECT_NE(err_.find("18 refreshes"), std::string::npos) << err_;
    EXPECT_NE(err_.find("100 ms late"), std::string::npos) << err_;  // 6 refreshes at 60 Hz
    EXPECT_NE(err_.find("close other programs"), std::string::npos) << err_;
    EXPECT_NE(err_.find("vertical sync"), std::string::npos) << err_;
    EXPECT_NE(err_.find("--resume"), std::string::npos) << err_;
}

TEST_F(MissedBound, AStallOnEveryTrialStopsAtThePerSessionBound) {
    // The defaults: 5 in a row, 10 % of the 4 trials: ceil(0.4) = 1 missed
    // allowed, so the second stops the run before the consecutive bound.
    const fs::path protocol = kData / "screen_stall.toml";
    const fs::path db = dir_.path() / "s.db";
    const int status = run(protocol, db, kStallEveryTrial);
    if (skipped_) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << err_;
    ASSERT_EQ(status, 7) << err_;
    ASSERT_EQ(trials(db).size(), 2u);
    const store::SessionRecord s = session(db);
    ASSERT_TRUE(s.stop_json.has_value());
    const nlohmann::json stop = store::parse_json(*s.stop_json).at(0);
    EXPECT_EQ(stop.at("reason"), "missed_per_session");
    EXPECT_EQ(stop.at("missed_this_run"), 2);
    EXPECT_EQ(stop.at("max_missed_this_run"), 1);
    EXPECT_EQ(stop.at("max_missed_in_a_row"), 5);
    EXPECT_NE(err_.find("max_missed_fraction"), std::string::npos) << err_;
}

TEST_F(MissedBound, WithoutRepeatMissedNothingIsBounded) {
    // Missed trials then count (marked): the schedule ends by itself.
    std::string text = file_bytes(protocol_copy(dir_, "max_missed_in_a_row = 1"));
    text.replace(text.find("repeat_missed = true"), 20, "repeat_missed = false");
    const fs::path protocol = dir_.path() / "norepeat.toml";
    std::ofstream(protocol) << text;
    const fs::path db = dir_.path() / "s.db";
    const int status = run(protocol, db, kStallEveryTrial);
    if (skipped_) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << err_;
    ASSERT_EQ(status, 0) << err_;
    EXPECT_EQ(trials(db).size(), 4u);
    EXPECT_FALSE(session(db).stop_json.has_value());
}

TEST_F(MissedBound, AStoppedSessionResumesAndCompletesAsAnUninterruptedOne) {
    const fs::path protocol = kData / "screen_stall.toml";
    const fs::path full_db = dir_.path() / "full.db";
    const int status = run(protocol, full_db, {});
    if (skipped_) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << err_;
    ASSERT_EQ(status, 0) << err_;
    const auto want = trials(full_db);
    ASSERT_EQ(want.size(), 4u);

    // Stopped twice (each run stops at its second missed presentation), then completed.
    const fs::path db = dir_.path() / "stopped.db";
    ASSERT_EQ(run(protocol, db, kStallEveryTrial), 7) << err_;
    std::vector<std::string> again = kStallEveryTrial;
    again.push_back("--resume-last");
    ASSERT_EQ(run(protocol, db, again), 7) << err_;
    EXPECT_EQ(trials(db).size(), 4u);
    ASSERT_EQ(run(protocol, db, {"--resume-last"}), 0) << err_;

    const store::SessionRecord s = session(db);
    EXPECT_EQ(s.status, store::SessionStatus::completed);
    EXPECT_EQ(s.resume_count, 2);
    ASSERT_TRUE(s.stop_json.has_value()) << "the stops are kept when the session completes";
    const nlohmann::json stops = store::parse_json(*s.stop_json);
    ASSERT_EQ(stops.size(), 2u);
    EXPECT_EQ(stops[0].at("trials_stored"), 2);
    EXPECT_EQ(stops[1].at("trials_stored"), 4);

    const auto got = trials(db);
    ASSERT_EQ(got.size(), 4u + 4u) << "4 missed (shown again), then the 4 the procedure saw";
    std::vector<TrialRecord> counted;
    for (const TrialRecord& r : got)
        if (r.response != "missed") counted.push_back(r);
    ASSERT_EQ(counted.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
        SCOPED_TRACE(i);
        EXPECT_EQ(counted[i].condition_id, want[i].condition_id);
        EXPECT_EQ(counted[i].procedure_id, want[i].procedure_id);
        EXPECT_EQ(counted[i].level, want[i].level);
        EXPECT_EQ(counted[i].test_on_left, want[i].test_on_left);
        EXPECT_EQ(counted[i].response, want[i].response);
        EXPECT_FALSE(counted[i].missed_deadline);
    }

    // analyze shows the stops.
    const test::Captured an = test::atonlab(
        {"analyze", db.string(), "--out", (dir_.path() / "report").string(), "--bootstrap", "0"}, dir_.path(), "an");
    ASSERT_EQ(an.code, 0) << an.err;
    EXPECT_NE(an.out.find("was stopped by the runner 2 time(s) (status completed)"), std::string::npos) << an.out;
    const std::string summary = file_bytes(dir_.path() / "report" / "summary.json");
    EXPECT_NE(summary.find("\"stop_reason\": \"missed_per_session\""), std::string::npos) << summary;
    EXPECT_NE(file_bytes(dir_.path() / "report" / "report.html").find("stopped by the runner"), std::string::npos);
}

}  // namespace
}  // namespace atonlab
