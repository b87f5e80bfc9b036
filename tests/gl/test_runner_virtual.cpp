// The full-screen runner's trial rules on the headless virtual display
// (`atonlab run --headless`: the same flip loop and frame clock as on screen,
// flips at k / 60 s exactly), where every number is exact:
//  - an injected stall of N refreshes marks its trial (missed_deadline,
//    dropped_frames = N) and, with repeat_missed, stores it as "missed", shows
//    the same proposal again and lets the procedure see one answer;
//  - a session stopped after a missed trial resumes past it (the replay skips
//    it) and ends trial for trial as the uninterrupted one;
//  - an answer later than response_timeout_s is stored as "timeout" and the
//    trial is shown again;
//  - durations are whole frames: onsets and response times are k / 60.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "../support/child_process.h"
#include "atonlab/store/sha256.h"
#include "atonlab/store/store.h"
#include "../support/skip.h"

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

/// screen_stall.toml with its scene path made absolute and `extra` added to [timing].
fs::path protocol_copy(const TempDir& dir, const std::string& name, const std::string& timing_extra,
                       bool repeat_missed = true) {
    std::string text = file_bytes(kData / "screen_stall.toml");
    text.replace(text.find("\"screen.scene.toml\""), 19, "\"" + (kData / "screen.scene.toml").string() + "\"");
    if (!repeat_missed) text.replace(text.find("repeat_missed = true"), 20, "repeat_missed = false");
    text.replace(text.find("[timing]\n"), 9, "[timing]\n" + timing_extra + "\n");
    const fs::path p = dir.path() / name;
    std::ofstream(p) << text;
    return p;
}

void write_script(const fs::path& path, const std::vector<std::string>& lines) {
    std::ofstream f(path);
    for (const std::string& l : lines) f << l << "\n";
}

class RunnerVirtual : public ::testing::Test {
protected:
    int run(const fs::path& protocol, const fs::path& db, std::vector<std::string> extra) {
        std::vector<std::string> args{"run",        protocol.string(), "--db",         db.string(),
                                      "--headless", "--quiet",         "--no-true-pse"};
        args.insert(args.end(), extra.begin(), extra.end());
        const test::Captured r = test::atonlab(std::move(args), dir_.path());
        err_ = r.err;
        if (r.code == 3) skipped_ = true;
        return r.code;
    }
    const std::string& err() const { return err_; }
    std::vector<TrialRecord> trials(const fs::path& db) {
        Store s = Store::open_read_only(db);
        return s.trials(s.sessions().back().id);
    }
    TempDir dir_;
    bool skipped_ = false;
    std::string err_;  ///< the last run's stderr
};

TEST_F(RunnerVirtual, AStallMarksItsTrialWhichIsShownAgain) {
    const fs::path db = dir_.path() / "s.db";
    const int status = run(kData / "screen_stall.toml", db,
                           {"--model-observer", "--inject-stall-frames", "6", "--inject-stall-at-trial", "1"});
    if (skipped_) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << err();
    ASSERT_EQ(status, 0) << err();
    const auto t = trials(db);
    ASSERT_EQ(t.size(), 5u);
    for (std::size_t i = 0; i < t.size(); ++i) {
        SCOPED_TRACE(i);
        EXPECT_EQ(t[i].trial_index, static_cast<std::int64_t>(i));
        EXPECT_EQ(t[i].missed_deadline, i == 1);
        // Headless the only late flip is the injected one: 6 refreshes lost, exactly.
        EXPECT_EQ(t[i].dropped_frames, i == 1 ? 6 : 0);
        EXPECT_EQ(t[i].response == "missed", i == 1) << t[i].response;
    }
    EXPECT_EQ(t[2].procedure_id, t[1].procedure_id);
    EXPECT_EQ(t[2].level, t[1].level);
    EXPECT_EQ(t[2].test_on_left, t[1].test_on_left);
    EXPECT_NE(t[1].procedure_state_json.find("\"answer\":"), std::string::npos) << "the answer given is kept";
    // The procedure saw 4 answers: the stored schedule state of the repeat says step 1, as the missed one.
    EXPECT_NE(t[1].procedure_state_json.find("\"step\":1"), std::string::npos) << t[1].procedure_state_json;
    EXPECT_NE(t[2].procedure_state_json.find("\"step\":1"), std::string::npos) << t[2].procedure_state_json;
    EXPECT_NE(t[4].procedure_state_json.find("\"step\":3"), std::string::npos);
    // Onsets on the 60 Hz grid: the first after the 0.1 s fixation is refresh 6.
    EXPECT_DOUBLE_EQ(t[0].onset_time_s, 6.0 / 60.0);
    for (const TrialRecord& r : t) {
        EXPECT_NEAR(r.onset_time_s * 60.0, std::round(r.onset_time_s * 60.0), 1e-6) << r.onset_time_s;
        EXPECT_NE(r.stimulus_json.find("\"stimulus_frames\":12,\"inter_stimulus_frames\":6,\"inter_trial_frames\":6"),
                  std::string::npos)
            << r.stimulus_json;
    }
}

TEST_F(RunnerVirtual, WithoutRepeatMissedTheStalledTrialCounts) {
    const fs::path protocol = protocol_copy(dir_, "p.toml", "", false);
    const fs::path db = dir_.path() / "s.db";
    const int status =
        run(protocol, db, {"--model-observer", "--inject-stall-frames", "3", "--inject-stall-at-trial", "0"});
    if (skipped_) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << err();
    ASSERT_EQ(status, 0) << err();
    const auto t = trials(db);
    ASSERT_EQ(t.size(), 4u);
    EXPECT_TRUE(t[0].missed_deadline);
    EXPECT_EQ(t[0].dropped_frames, 3);
    EXPECT_TRUE(t[0].response == "left" || t[0].response == "right");
}

TEST_F(RunnerVirtual, AResumedSessionSkipsTheMissedTrialAsTheLiveOneDid) {
    const fs::path protocol = kData / "screen_stall.toml";
    const std::vector<std::string> answers{"left 0.3", "right 0.2", "left 0.1", "right 0.4", "left 0.2"};
    const std::vector<std::string> stall{"--inject-stall-frames", "4", "--inject-stall-at-trial", "1"};
    // Uninterrupted.
    const fs::path full_script = dir_.path() / "all.txt";
    write_script(full_script, answers);
    const fs::path full_db = dir_.path() / "full.db";
    std::vector<std::string> args{"--script", full_script.string()};
    args.insert(args.end(), stall.begin(), stall.end());
    const int status = run(protocol, full_db, args);
    if (skipped_) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << err();
    ASSERT_EQ(status, 0) << err();
    const auto want = trials(full_db);
    ASSERT_EQ(want.size(), 5u);
    ASSERT_EQ(want[1].response, "missed");

    // The script runs out after three rows (the missed one among them): the
    // session stays open; resumed with the whole script it skips the lines used.
    const fs::path part_script = dir_.path() / "part.txt";
    write_script(part_script, {answers[0], answers[1], answers[2]});
    const fs::path db = dir_.path() / "resumed.db";
    args = {"--script", part_script.string()};
    args.insert(args.end(), stall.begin(), stall.end());
    ASSERT_EQ(run(protocol, db, args), 2) << err();
    ASSERT_EQ(trials(db).size(), 3u);
    write_script(part_script, answers);
    ASSERT_EQ(run(protocol, db, {"--script", part_script.string(), "--resume-last"}), 0) << err();
    const auto got = trials(db);
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
        SCOPED_TRACE(i);
        EXPECT_EQ(got[i].procedure_id, want[i].procedure_id);
        EXPECT_EQ(got[i].level, want[i].level);
        EXPECT_EQ(got[i].test_on_left, want[i].test_on_left);
        EXPECT_EQ(got[i].response, want[i].response);
        EXPECT_EQ(got[i].missed_deadline, want[i].missed_deadline);
        EXPECT_EQ(got[i].dropped_frames, want[i].dropped_frames);
        EXPECT_NEAR(got[i].onset_time_s, want[i].onset_time_s, 1e-9);
        EXPECT_NEAR(got[i].response_time_s, want[i].response_time_s, 1e-9);
    }
}

// Issue 24: the study stores the scene text with its SHA-256 beside the
// protocol; a session continues only with the scene it began with, as with
// its protocol text (and the conditions files stored in it).
TEST_F(RunnerVirtual, TheSceneIsStoredAndAResumeWithAnEditedSceneIsRefused) {
    const fs::path protocol = dir_.path() / "screen_stall.toml";
    const fs::path scene = dir_.path() / "screen.scene.toml";
    std::ofstream(protocol) << file_bytes(kData / "screen_stall.toml");
    const std::string scene_text = file_bytes(kData / "screen.scene.toml");
    std::ofstream(scene) << scene_text;
    const fs::path script = dir_.path() / "part.txt";
    write_script(script, {"left 0.3", "right 0.2"});
    const fs::path db = dir_.path() / "study.db";
    const int status = run(protocol, db, {"--script", script.string()});
    if (skipped_) GTEST_SKIP() << "no GL 4.5 context: " << err();
    ASSERT_EQ(status, 2) << err();  // the script ran out: the session stays open
    {
        Store s = Store::open_read_only(db);
        const store::SessionRecord r = s.sessions().back();
        EXPECT_EQ(r.scene_sha256, store::sha256_hex(scene_text));
        EXPECT_EQ(r.scene_name, "screen.scene.toml");
        EXPECT_EQ(s.scene_text(r.id), scene_text);
    }
    const std::size_t before = trials(db).size();
    std::ofstream(scene, std::ios::app) << "# edited\n";
    write_script(script, {"left 0.3", "right 0.2", "left 0.1", "right 0.4", "left 0.2"});
    EXPECT_EQ(run(protocol, db, {"--script", script.string(), "--resume-last"}), 2);
    EXPECT_NE(err().find("ran a different text of this scene"), std::string::npos) << err();
    EXPECT_NE(err().find("screen.scene.toml"), std::string::npos) << err();
    EXPECT_EQ(trials(db).size(), before);
    std::ofstream(scene) << scene_text;  // the scene it began with: it continues
    EXPECT_EQ(run(protocol, db, {"--script", script.string(), "--resume-last"}), 0) << err();
}

TEST_F(RunnerVirtual, ALateAnswerTimesOutAndTheTrialIsShownAgain) {
    const fs::path protocol = protocol_copy(dir_, "timeout.toml", "response_timeout_s = 0.5");
    const fs::path script = dir_.path() / "a.txt";
    // The second answer comes 2 s after the stimulus: past the 0.5 s timeout.
    write_script(script, {"left 0.2", "right 2.0", "right 0.1", "left 0.1", "left 0.3"});
    const fs::path db = dir_.path() / "t.db";
    const int status = run(protocol, db, {"--script", script.string()});
    if (skipped_) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << err();
    ASSERT_EQ(status, 0) << err();
    const auto t = trials(db);
    ASSERT_EQ(t.size(), 5u);
    EXPECT_EQ(t[1].response, "timeout");
    EXPECT_FALSE(t[1].missed_deadline);
    // Onset to timeout: the presentation (12 + 6 + 12 frames = 0.5 s) and the 0.5 s.
    EXPECT_NEAR(t[1].response_time_s, 0.5 + 0.5, 1e-12);
    EXPECT_EQ(t[2].procedure_id, t[1].procedure_id);
    EXPECT_EQ(t[2].level, t[1].level);
    EXPECT_EQ(t[2].test_on_left, t[1].test_on_left);
    EXPECT_EQ(t[2].response, "right");
    EXPECT_NEAR(t[2].response_time_s, 0.5 + 0.1, 1e-12);
    EXPECT_EQ(t[0].response, "left");
    EXPECT_NEAR(t[0].response_time_s, 0.5 + 0.2, 1e-12);
    // The next fixation starts at the first refresh after the timeout.
    EXPECT_NEAR(t[2].onset_time_s, std::ceil((t[1].onset_time_s + 1.0) * 60.0 - 1e-7) / 60.0 + 0.1, 1e-9);
}

}  // namespace
}  // namespace atonlab
