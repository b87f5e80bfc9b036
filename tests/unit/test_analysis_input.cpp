// `atonlab analyze`'s input (analysis/include/atonlab/analysis/dataset.h):
// study files read read-only and merged, the long-format CSV, and the tidy
// trials.csv read back. The study files are made without GL by
// analysis_test_data.h (a protocol's Schedule answered by a simulated
// observer), so every expected value is known independently of the reader.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "../store/store_test_support.h"
#include "analysis_test_data.h"
#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/report.h"
#include "atonlab/analysis/study_analysis.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"

namespace atonlab::analysis {
namespace {

namespace fs = std::filesystem;
using store::test_support::RawDb;
using store::test_support::TempDir;
namespace td = test_data;

void write(const fs::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
}

/// The InputError's message, or "" when `f` does not throw one.
template <class F>
InputError expect_input_error(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "no InputError";
    return InputError("");
}

// --- CSV --------------------------------------------------------------------------

TEST(AnalysisCsv, MinimalColumnsGiveOutcomesAndSessions) {
    TempDir dir;
    write(dir / "t.csv",
          "observer,condition,level,response\n"
          "P1,c,1.5,1\n"
          "P1,c,2.5,yes\n"
          "P2,c,1.5,0\n"
          "P2,c,2.5,false\n");
    const Dataset d = read_trials_csv(dir / "t.csv");
    ASSERT_EQ(d.trials.size(), 4u);
    EXPECT_EQ(d.trials[0].observer, "P1");
    EXPECT_EQ(d.trials[0].level, 1.5);
    EXPECT_EQ(d.trials[0].outcome, std::optional<bool>(true));
    EXPECT_EQ(d.trials[1].outcome, std::optional<bool>(true));
    EXPECT_EQ(d.trials[2].outcome, std::optional<bool>(false));
    EXPECT_EQ(d.trials[3].outcome, std::optional<bool>(false));
    // Without a session column each observer is one session; trial indices count per session.
    ASSERT_EQ(d.sessions.size(), 2u);
    EXPECT_NE(d.trials[0].session, d.trials[2].session);
    EXPECT_EQ(d.trials[1].trial_index, 1);
    EXPECT_EQ(d.trials[2].trial_index, 0);
    EXPECT_EQ(d.trials[0].task, protocols::Task::TwoAfc);
    EXPECT_EQ(d.trials[0].level_scale, "log10");
}

TEST(AnalysisCsv, SideAnswersAreScoredWithTestOnLeft) {
    TempDir dir;
    // level on the reference: choosing the side that is not the test = chose the reference = 1.
    write(dir / "t.csv",
          "observer,condition,level,response,test_on_left,level_on\n"
          "P,c,1,left,1,reference\n"
          "P,c,1,right,1,reference\n"
          "P,c,1,left,0,reference\n"
          "P,c,1,left,1,test\n");
    const Dataset d = read_trials_csv(dir / "t.csv");
    ASSERT_EQ(d.trials.size(), 4u);
    EXPECT_EQ(d.trials[0].outcome, std::optional<bool>(false));
    EXPECT_EQ(d.trials[1].outcome, std::optional<bool>(true));
    EXPECT_EQ(d.trials[2].outcome, std::optional<bool>(true));
    EXPECT_EQ(d.trials[3].outcome, std::optional<bool>(true));
}

TEST(AnalysisCsv, QuotedFieldsAndCrlf) {
    TempDir dir;
    write(dir / "t.csv", "observer,condition,level,response\r\n\"P,1\",\"a \"\"b\"\"\",2,1\r\n");
    const Dataset d = read_trials_csv(dir / "t.csv");
    ASSERT_EQ(d.trials.size(), 1u);
    EXPECT_EQ(d.trials[0].observer, "P,1");
    EXPECT_EQ(d.trials[0].condition, "a \"b\"");
    EXPECT_EQ(d.trials[0].outcome, std::optional<bool>(true));
}

TEST(AnalysisCsv, DeprecatedQuestColumnsAreReadAsThePosteriorsWithANote) {
    TempDir dir;
    write(
        dir / "old.csv",
        "observer,condition,level,response,quest_mean,quest_sd,quest_lower,quest_upper\nP,c,-1,1,-1.5,0.2,-1.9,-1.1\n");
    const Dataset d = read_trials_csv(dir / "old.csv");
    ASSERT_EQ(d.trials.size(), 1u);
    EXPECT_EQ(d.trials[0].posterior_mean, std::optional<double>(-1.5));
    EXPECT_EQ(d.trials[0].posterior_sd, std::optional<double>(0.2));
    EXPECT_EQ(d.trials[0].posterior_lower, std::optional<double>(-1.9));
    EXPECT_EQ(d.trials[0].posterior_upper, std::optional<double>(-1.1));
    ASSERT_EQ(d.notes.size(), 1u);
    EXPECT_NE(d.notes[0].find("quest_mean as posterior_mean"), std::string::npos) << d.notes[0];
    // The new name wins where a file has both; the old column is then not used.
    write(dir / "both.csv", "observer,condition,level,response,quest_mean,posterior_mean\nP,c,-1,1,-1.5,-1.25\n");
    const Dataset both = read_trials_csv(dir / "both.csv");
    EXPECT_EQ(both.trials[0].posterior_mean, std::optional<double>(-1.25));
}

TEST(AnalysisCsv, MissingRequiredColumnNamesItAndLineOne) {
    TempDir dir;
    write(dir / "t.csv", "observer,condition,response\nP,c,1\n");
    const InputError e = expect_input_error([&] { read_trials_csv(dir / "t.csv"); });
    ASSERT_TRUE(e.where());
    EXPECT_EQ(e.where()->line, 1);
    EXPECT_EQ(e.where()->key, "level");
    EXPECT_TRUE(e.where()->key_is_column);
    EXPECT_NE(std::string(e.what()).find("t.csv:1: column 'level'"), std::string::npos) << e.what();
}

TEST(AnalysisCsv, BadValuesNameLineAndColumn) {
    TempDir dir;
    struct Case {
        std::string row;
        std::string column;
    };
    for (const Case& c : {Case{"P,c,abc,1", "level"}, Case{"P,c,nan,1", "level"}, Case{"P,c,1,maybe", "response"},
                          Case{",c,1,1", "observer"}, Case{"P,c,1,1,0.5x", "guess_rate"}}) {
        const std::string header = c.column == "guess_rate" ? "observer,condition,level,response,guess_rate\n"
                                                            : "observer,condition,level,response\n";
        write(dir / "t.csv", header + "P,c,1,1" + (c.column == "guess_rate" ? ",0" : "") + "\n" + c.row + "\n");
        const InputError e = expect_input_error([&] { read_trials_csv(dir / "t.csv"); });
        ASSERT_TRUE(e.where()) << c.row;
        EXPECT_EQ(e.where()->line, 3) << c.row << ": " << e.what();
        EXPECT_EQ(e.where()->key, c.column) << c.row << ": " << e.what();
    }
}

TEST(AnalysisCsv, StructuralErrors) {
    TempDir dir;
    write(dir / "empty.csv", "");
    EXPECT_EQ(expect_input_error([&] { read_trials_csv(dir / "empty.csv"); }).where().value_or(SourceLocation{}).line,
              1);
    write(dir / "header-only.csv", "observer,condition,level,response\n");
    EXPECT_NE(
        std::string(expect_input_error([&] { read_trials_csv(dir / "header-only.csv"); }).what()).find("no trials"),
        std::string::npos);
    write(dir / "short.csv", "observer,condition,level,response\nP,c,1\n");
    EXPECT_EQ(expect_input_error([&] { read_trials_csv(dir / "short.csv"); }).where().value_or(SourceLocation{}).line,
              2);
    write(dir / "quote.csv", "observer,condition,level,response\nP,\"c,1,1\n");
    EXPECT_NE(std::string(expect_input_error([&] { read_trials_csv(dir / "quote.csv"); }).what()).find("never closed"),
              std::string::npos);
    write(dir / "dup.csv", "observer,condition,level,level,response\nP,c,1,1,1\n");
    EXPECT_EQ(expect_input_error([&] { read_trials_csv(dir / "dup.csv"); }).where().value_or(SourceLocation{}).key,
              "level");
    EXPECT_NE(
        std::string(expect_input_error([&] { read_trials_csv(dir / "missing.csv"); }).what()).find("cannot be opened"),
        std::string::npos);
}

// --- study files --------------------------------------------------------------------

TEST(AnalysisStudy, ReadsEveryTrialWithItsStimulusParameters) {
    TempDir dir;
    const std::string text = td::constant_stimuli_protocol(2);
    td::run_simulated(dir / "s.db", text, td::sim("A", 2.0, 0.1));
    const Dataset d = read_study(dir / "s.db");
    ASSERT_EQ(d.sessions.size(), 1u);
    ASSERT_EQ(d.trials.size(), 2u * 7u * 2u);  // 2 conditions x 7 levels x 2 repetitions
    const Trial& t = d.trials.front();
    EXPECT_EQ(t.task, protocols::Task::TwoAfc);
    EXPECT_EQ(t.procedure, "constant-stimuli");
    EXPECT_EQ(t.level_key, "light.reference.intensity_cd");
    EXPECT_EQ(t.level_on, "reference");
    ASSERT_TRUE(t.adaptation_cd_m2.has_value());
    EXPECT_EQ(*t.adaptation_cd_m2, 0.001);
    EXPECT_EQ(t.glare_test, "wave-optics");
    EXPECT_EQ(t.glare_reference, "none");
    ASSERT_TRUE(t.test_intensity_cd.has_value());
    EXPECT_EQ(*t.test_intensity_cd, 100.0);
    EXPECT_EQ(t.guess_rate, 0.0);
    EXPECT_EQ(t.target_p, 0.5);
    std::set<std::string> tone;
    for (const Trial& x : d.trials) tone.insert(x.tone_operator);
    EXPECT_EQ(tone, (std::set<std::string>{"empirical", "perceptual"}));
    // The outcome agrees with the side answer and where the test was, trial by trial, read raw.
    RawDb raw(dir / "s.db", SQLITE_OPEN_READONLY);
    const std::string responses = raw.text("SELECT response || test_on_left FROM trials ORDER BY trial_index");
    std::size_t i = 0;
    for (std::size_t at = 0; at < responses.size(); ++i) {
        const std::size_t nl = responses.find('\n', at);
        const std::string row = responses.substr(at, nl == std::string::npos ? std::string::npos : nl - at);
        at = nl == std::string::npos ? responses.size() : nl + 1;
        const bool left = row.rfind("left", 0) == 0;
        const bool test_left = row.back() == '1';
        EXPECT_EQ(*d.trials[i].outcome, left != test_left) << "trial " << i;  // chose the reference
    }
    EXPECT_EQ(i, d.trials.size());
}

TEST(AnalysisStudy, MergedStudiesKeepObserversAndSessionsApart) {
    TempDir dir;
    const std::string text = td::constant_stimuli_protocol(3);
    td::run_simulated(dir / "a.db", text, td::sim("A", 1.9, 0.1, 1));
    td::run_simulated(dir / "b.db", text, td::sim("B", 2.1, 0.1, 2));
    // A second session of A in b.db: observer A spans two files.
    td::run_simulated(dir / "b.db", text, td::sim("A", 1.9, 0.1, 3), 8);
    Dataset d = read_study(dir / "a.db");
    merge(d, read_study(dir / "b.db"));
    ASSERT_EQ(d.sessions.size(), 3u);
    std::set<std::string> keys;
    for (const SessionInfo& s : d.sessions) keys.insert(s.key);
    EXPECT_EQ(keys.size(), 3u) << "session 1 of a.db and session 1 of b.db must not merge";
    std::map<std::string, int> per_observer, per_session;
    for (const Trial& t : d.trials) {
        ++per_observer[t.observer];
        ++per_session[t.session];
    }
    const int per = 2 * 7 * 3;
    EXPECT_EQ(per_observer["A"], 2 * per);
    EXPECT_EQ(per_observer["B"], per);
    for (const auto& [k, n] : per_session) EXPECT_EQ(n, per) << k;

    AnalysisOptions o;
    o.bootstrap = 0;
    const StudyResults r = analyze_study(d, o);
    EXPECT_EQ(r.observers, (std::vector<std::string>{"A", "B"}));
    for (const GroupResult& g : r.groups) {
        const int sessions = g.observer == "A" ? 2 : g.observer == "B" ? 1 : 3;
        // Per condition: 7 levels x 3 repetitions per session.
        EXPECT_EQ(g.n_sessions, sessions) << g.condition << " " << g.observer;
        EXPECT_EQ(g.n_trials, sessions * 7 * 3) << g.condition << " " << g.observer;
    }
    // Two observers, two conditions that differ only in the tone mapper: one paired comparison.
    ASSERT_EQ(r.paired.size(), 1u);
    EXPECT_EQ(r.paired[0].factor, "tone mapper");
    EXPECT_EQ(r.paired[0].comparison.n, 2);
    EXPECT_EQ(r.paired[0].observers, (std::vector<std::string>{"A", "B"}));
    // The same file twice is refused.
    Dataset twice = read_study(dir / "a.db");
    EXPECT_THROW(merge(twice, read_study(dir / "a.db")), InputError);
}

TEST(AnalysisStudy, StaircaseReversalsAndQuestPosteriorsMatchTheProceduresOwn) {
    TempDir dir;
    namespace p = atonlab::protocols;
    for (const std::string& text : {td::staircase_protocol(), td::quest_protocol()}) {
        const fs::path db = dir / (text.find("quest") != std::string::npos ? "q.db" : "s.db");
        td::run_simulated(db, text, td::sim("A", 2.0, 0.15, 9));
        const Dataset d = read_study(db);
        EXPECT_TRUE(d.notes.empty()) << d.notes.front();
        // The procedures' estimates after replaying the same answers through the Schedule.
        const p::Protocol protocol = p::parse_protocol(text, "sim.toml");
        std::vector<p::Response> answers;
        for (const Trial& t : d.trials) {
            if (t.task == protocols::Task::TwoAfc)
                answers.push_back(t.response == "left" ? p::Response::Left : p::Response::Right);
            else
                answers.push_back(t.response == "yes" ? p::Response::Yes : p::Response::No);
        }
        const p::Schedule replayed = p::Schedule::replay(protocol, 7, answers);
        AnalysisOptions o;
        o.bootstrap = 0;
        o.last_reversals = 6;  // the staircase protocol's estimate_reversals
        const StudyResults r = analyze_study(d, o);
        for (const p::TrackResult& tr : replayed.results()) {
            const TrackResult* mine = nullptr;
            for (const GroupResult& g : r.groups)
                for (const TrackResult& t : g.tracks)
                    if (t.track == tr.procedure_id) mine = &t;
            ASSERT_NE(mine, nullptr) << tr.procedure_id;
            if (mine->procedure == "quest") {
                ASSERT_TRUE(mine->posterior && mine->posterior->mean && mine->posterior->sd);
                EXPECT_DOUBLE_EQ(*mine->posterior->mean, tr.estimate.value) << tr.procedure_id;
                EXPECT_DOUBLE_EQ(*mine->posterior->sd, tr.estimate.sd) << tr.procedure_id;
                ASSERT_TRUE(mine->posterior->interval);
                EXPECT_LT(mine->posterior->interval->lower, *mine->posterior->mean);
                EXPECT_GT(mine->posterior->interval->upper, *mine->posterior->mean);
            } else {
                ASSERT_TRUE(mine->reversals && mine->reversals->mean) << tr.procedure_id;
                // Within 1e-12: the analysis takes the levels without the noise of
                // decimal steps summed in binary (csv.h level_value); the procedure's own
                // mean is of the noisy ones.
                EXPECT_NEAR(*mine->reversals->mean, tr.estimate.value, 1e-12) << tr.procedure_id;
                EXPECT_EQ(static_cast<std::size_t>(mine->reversals->n_used), tr.estimate.n);
            }
        }
    }
}

TEST(AnalysisStudy, ReadableWhileASessionRunsAndNeverWritten) {
    TempDir dir;
    const std::string text = td::staircase_protocol();
    td::run_simulated(dir / "s.db", text, td::sim("A"), 7, /*finish=*/false, 10);
    // A writer holds the file open (as a running session does) while it is read.
    store::Store writer = store::Store::open_existing(dir / "s.db");
    const std::string before = store::test_support::file_bytes(dir / "s.db");
    const Dataset d = read_study(dir / "s.db");
    ASSERT_EQ(d.sessions.size(), 1u);
    EXPECT_EQ(d.sessions[0].status, "running");
    EXPECT_EQ(d.trials.size(), 10u);
    EXPECT_EQ(store::test_support::file_bytes(dir / "s.db"), before);
}

TEST(AnalysisStudy, RefusesWhatIsNotAStudy) {
    TempDir dir;
    write(dir / "notes.db", "these are not the trials you are looking for\n");
    try {
        read_study(dir / "notes.db");
        ADD_FAILURE() << "no error";
    } catch (const store::StoreError& e) {
        EXPECT_EQ(e.kind(), store::StoreErrc::not_a_database) << e.what();
    }
    td::run_simulated(dir / "new.db", td::staircase_protocol(), td::sim("A"), 7, true, 3);
    {
        RawDb raw(dir / "new.db");
        ASSERT_EQ(raw.exec("PRAGMA user_version = 999"), "");
    }
    const std::string before = store::test_support::file_bytes(dir / "new.db");
    try {
        read_study(dir / "new.db");
        ADD_FAILURE() << "no error";
    } catch (const store::StoreError& e) {
        EXPECT_EQ(e.kind(), store::StoreErrc::newer_schema) << e.what();
    }
    EXPECT_EQ(store::test_support::file_bytes(dir / "new.db"), before);
}

// --- trials.csv round trip -------------------------------------------------------------

TEST(AnalysisCsv, TrialsCsvRoundTripGivesTheSameTrialsAndFits) {
    TempDir dir;
    td::run_simulated(dir / "a.db", td::constant_stimuli_protocol(4), td::sim("A", 1.95, 0.12));
    td::run_simulated(dir / "a.db", td::staircase_protocol(), td::sim("B", 2.05, 0.1, 4));
    td::run_simulated(dir / "q.db", td::quest_protocol(), td::sim("A", 0.3, 0.2, 1, 0.02));
    Dataset d = read_study(dir / "a.db");
    merge(d, read_study(dir / "q.db"));
    write_trials_csv(dir / "trials.csv", d);
    const Dataset back = read_trials_csv(dir / "trials.csv");
    ASSERT_EQ(back.trials.size(), d.trials.size());
    for (std::size_t i = 0; i < d.trials.size(); ++i) {
        const Trial& a = d.trials[i];
        const Trial& b = back.trials[i];
        EXPECT_EQ(a.session, b.session);
        EXPECT_EQ(a.observer, b.observer);
        EXPECT_EQ(a.trial_index, b.trial_index);
        EXPECT_EQ(a.condition, b.condition);
        EXPECT_EQ(a.track, b.track);
        EXPECT_EQ(a.procedure, b.procedure);
        EXPECT_EQ(a.task, b.task);
        EXPECT_EQ(a.level, b.level);  // exact: shortest round-trip text
        EXPECT_EQ(a.outcome, b.outcome);
        EXPECT_EQ(a.test_on_left, b.test_on_left);
        EXPECT_EQ(a.adaptation_cd_m2, b.adaptation_cd_m2);
        EXPECT_EQ(a.tone_operator, b.tone_operator);
        EXPECT_EQ(a.test_intensity_cd, b.test_intensity_cd);
        EXPECT_EQ(a.guess_rate, b.guess_rate);
        EXPECT_EQ(a.target_p, b.target_p);
        EXPECT_EQ(a.reversal, b.reversal);
        EXPECT_EQ(a.posterior_mean, b.posterior_mean);
        EXPECT_EQ(a.posterior_upper, b.posterior_upper);
    }
    AnalysisOptions o;
    o.bootstrap = 60;
    const StudyResults ra = analyze_study(d, o);
    const StudyResults rb = analyze_study(back, o);
    write_fits_csv(dir / "fits-a.csv", ra);
    write_fits_csv(dir / "fits-b.csv", rb);
    // The same rows; their order follows the protocol's condition order, which a CSV does not carry.
    auto sorted_lines = [](const std::string& text) {
        std::vector<std::string> lines;
        std::istringstream in(text);
        for (std::string l; std::getline(in, l);) lines.push_back(l);
        std::sort(lines.begin(), lines.end());
        return lines;
    };
    const auto fa = sorted_lines(store::test_support::file_bytes(dir / "fits-a.csv"));
    EXPECT_GT(fa.size(), 10u);
    EXPECT_EQ(fa, sorted_lines(store::test_support::file_bytes(dir / "fits-b.csv")));
}

}  // namespace
}  // namespace atonlab::analysis
