// The procedure registry (protocols/procedures.h): every kind is found by its
// name and its enum, its parameters are its own alternative of
// ProcedureParams, it declares what analysis follows in its tracks as the
// literature describes the method, and its name is spelled once: a scan of
// protocols/, analysis/, runner/, python/, bench/ and present/ finds no string
// literal naming a kind outside the files listed below. docs/architecture.md
// "How to add a procedure" names the files a new kind touches; the last test
// holds it to them (and tests/unit/test_registries.cpp to the tree).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "atonlab/protocols/procedures.h"
#include "atonlab/protocols/protocol.h"

namespace {

namespace p = atonlab::protocols;
namespace fs = std::filesystem;

TEST(ProcedureRegistry, EveryKindIsFoundByItsNameAndItsEnum) {
    const auto types = p::procedure_types();
    ASSERT_EQ(types.size(), std::variant_size_v<p::ProcedureParams>);
    std::set<std::string_view> names;
    for (std::size_t i = 0; i < types.size(); ++i) {
        const p::ProcedureType& t = *types[i];
        SCOPED_TRACE(std::string(t.name));
        EXPECT_EQ(static_cast<std::size_t>(t.kind), i) << "kProcedureTypes is out of ProcedureKind's order";
        EXPECT_EQ(&p::procedure_type(t.kind), &t);
        EXPECT_EQ(p::find_procedure_type(t.name), &t);
        EXPECT_EQ(p::to_string(t.kind), t.name);
        EXPECT_EQ(p::parse_procedure_kind(t.name), t.kind);
        EXPECT_TRUE(names.insert(t.name).second) << "two kinds share a name";
        EXPECT_NE(std::find(t.keys.begin(), t.keys.end(), "kind"), t.keys.end());
        for (const void* f :
             {reinterpret_cast<const void*>(t.read), reinterpret_cast<const void*>(t.make),
              reinterpret_cast<const void*>(t.target_p_yes), reinterpret_cast<const void*>(t.level_bounds),
              reinterpret_cast<const void*>(t.search_range), reinterpret_cast<const void*>(t.max_trials_per_track),
              reinterpret_cast<const void*>(t.guess_rate), reinterpret_cast<const void*>(t.describe),
              reinterpret_cast<const void*>(t.track_state)})
            EXPECT_NE(f, nullptr);
    }
    EXPECT_EQ(p::find_procedure_type("interleaved"), nullptr);  // a wrapper, not a kind
    EXPECT_EQ(p::find_procedure_type("2afc"), nullptr);
    EXPECT_EQ(p::find_procedure_type(""), nullptr);
}

/// Alternative I of ProcedureParams, default-constructed, is the parameters of
/// kind I: its type's functions take it (std::get would throw otherwise).
template <std::size_t... I>
void check_alternatives(std::index_sequence<I...>) {
    (
        [] {
            const p::ProcedureParams params(std::in_place_index<I>);
            const p::ProcedureType& t = p::procedure_type(static_cast<p::ProcedureKind>(I));
            SCOPED_TRACE(std::string(t.name));
            EXPECT_NO_THROW((void)t.target_p_yes(params));
            EXPECT_NO_THROW((void)t.level_bounds(params));
            EXPECT_NO_THROW((void)t.max_trials_per_track(params));
            EXPECT_NO_THROW((void)t.describe(params));
        }(),
        ...);
}

TEST(ProcedureRegistry, EachKindTakesItsOwnParameters) {
    check_alternatives(std::make_index_sequence<std::variant_size_v<p::ProcedureParams>>{});
}

TEST(ProcedureRegistry, WhatAnalysisFollowsIsTheMethodsOwnEstimate) {
    // Levitt 1971 and Kaernbach 1991: a staircase's estimate is the mean of its
    // reversals; Watson & Pelli 1983: QUEST's is its posterior; constant
    // stimuli and adjustment have no track estimate (the fit, the matches).
    using E = p::TrackEstimate;
    EXPECT_EQ(p::Staircase::type().track_estimate, E::Reversals);
    EXPECT_EQ(p::WeightedStaircase::type().track_estimate, E::Reversals);
    EXPECT_EQ(p::Quest::type().track_estimate, E::Posterior);
    EXPECT_EQ(p::ConstantStimuli::type().track_estimate, E::None);
    EXPECT_EQ(p::Adjustment::type().track_estimate, E::None);
    // Only the method of adjustment takes the adjustment actions; QUEST's
    // Weibull is a function of log10 intensity.
    for (const p::ProcedureType* t : p::procedure_types()) {
        EXPECT_EQ(t->adjusts, t->kind == p::ProcedureKind::Adjustment) << t->name;
        EXPECT_EQ(!t->needs_log10.empty(), t->kind == p::ProcedureKind::Quest) << t->name;
    }
    // QUEST states its guess rate (gamma); the others leave it to the task.
    p::QuestParams q;
    q.gamma = 0.25;
    EXPECT_EQ(p::Quest::type().guess_rate(q), 0.25);
    EXPECT_EQ(p::Staircase::type().guess_rate(p::StaircaseParams{}), std::nullopt);
}

TEST(ProcedureRegistry, ReplayedStaircaseStateMarksItsReversals) {
    // A 1-up/1-down linear staircase from 0 in steps of 1 (no initial rule to
    // matter): Yes at 0 and -1 go down, No at -2 turns up (trial 2 reverses),
    // No at -1 goes up, Yes at 0 turns down (trial 4 reverses).
    p::StaircaseParams s;
    s.start = 0.0;
    s.step_sizes = {1.0};
    s.step_type = p::StepType::Lin;
    s.n_up = 1;
    s.n_down = 1;
    s.n_trials = 20;
    const p::ProcedureType& t = p::Staircase::type();
    std::unique_ptr<p::Procedure> proc = t.make(s, std::nullopt, 0);
    for (const p::Response r : {p::Response::Yes, p::Response::Yes, p::Response::No, p::Response::No, p::Response::Yes})
        proc->record(r);
    EXPECT_EQ(t.track_state(*proc).reversal_trials, (std::vector<std::size_t>{2, 4}));
    EXPECT_FALSE(t.track_state(*proc).mean);
    // A track start replaces the first level.
    EXPECT_EQ(t.make(s, 1.5, 0)->next()->level, 1.5);
}

TEST(ProcedureRegistry, ReplayedQuestStateIsItsPosterior) {
    // Before any answer QUEST's posterior is its prior: a normal of mean
    // t_guess and sd t_guess_sd (QuestCreate), so its 2.5% and 97.5% points
    // lie 1.96 sd either side (the grid's 0.01 grain bounds the error).
    p::QuestParams q;
    q.t_guess = -1.0;
    q.t_guess_sd = 0.5;
    q.n_trials = 10;
    const p::ProcedureType& t = p::Quest::type();
    const p::TrackState s = t.track_state(*t.make(q, std::nullopt, 0));
    ASSERT_TRUE(s.mean && s.sd && s.lower && s.upper);
    EXPECT_NEAR(*s.mean, -1.0, 1e-6);
    EXPECT_NEAR(*s.sd, 0.5, 0.01);
    EXPECT_NEAR(*s.lower, -1.0 - 1.96 * 0.5, 0.02);
    EXPECT_NEAR(*s.upper, -1.0 + 1.96 * 0.5, 0.02);
    EXPECT_TRUE(s.reversal_trials.empty());
}

// --- The names are spelled once ----------------------------------------------------

/// The string literals of C++ source `text`, unescaped (comments, character
/// literals and raw strings' delimiters skipped; raw strings kept).
std::vector<std::string> string_literals(const std::string& text) {
    std::vector<std::string> out;
    std::size_t i = 0;
    const std::size_t n = text.size();
    while (i < n) {
        const char c = text[i];
        if (c == '/' && i + 1 < n && text[i + 1] == '/') {
            i = text.find('\n', i);
            if (i == std::string::npos) break;
        } else if (c == '/' && i + 1 < n && text[i + 1] == '*') {
            i = text.find("*/", i + 2);
            if (i == std::string::npos) break;
            i += 2;
        } else if (c == '\'') {
            // A character literal ('"', '\''), or a digit separator (1'000).
            if (i > 0 && std::isalnum(static_cast<unsigned char>(text[i - 1])) && i + 1 < n &&
                std::isalnum(static_cast<unsigned char>(text[i + 1]))) {
                ++i;
                continue;
            }
            ++i;
            while (i < n && text[i] != '\'') i += text[i] == '\\' ? 2 : 1;
            ++i;
        } else if (c == 'R' && i + 1 < n && text[i + 1] == '"' &&
                   (i == 0 || !std::isalnum(static_cast<unsigned char>(text[i - 1])))) {
            const std::size_t open = text.find('(', i + 2);
            if (open == std::string::npos) break;
            const std::string close = ")" + text.substr(i + 2, open - i - 2) + "\"";
            const std::size_t end = text.find(close, open + 1);
            if (end == std::string::npos) break;
            out.push_back(text.substr(open + 1, end - open - 1));
            i = end + close.size();
        } else if (c == '"') {
            std::string s;
            ++i;
            while (i < n && text[i] != '"') {
                if (text[i] == '\\' && i + 1 < n) {
                    s += text[i + 1];
                    i += 2;
                } else {
                    s += text[i++];
                }
            }
            ++i;
            out.push_back(std::move(s));
        } else {
            ++i;
        }
    }
    return out;
}

TEST(ProcedureRegistry, TheLiteralScanFindsStringsNotComments) {
    const std::string src =
        "// \"quest\" in a comment\n/* \"quest\" */ char q = '\"'; int n = 1'000;\n"
        "auto a = \"quest\"; auto b = \"kind = \\\"quest\\\"\"; auto c = R\"x(raw \"quest\")x\";\n";
    EXPECT_EQ(string_literals(src), (std::vector<std::string>{"quest", "kind = \"quest\"", "raw \"quest\""}));
}

TEST(ProcedureRegistry, NamesAreSpelledOnlyInTheRegistry) {
    const fs::path root(ATONLAB_SOURCE_DIR);
    // Where a literal may spell a kind's name, and why.
    const std::map<std::string, std::set<std::string>> allowed = {
        // The one spelling: each class's kName.
        {"protocols/include/atonlab/protocols/staircase.h", {"staircase"}},
        {"protocols/include/atonlab/protocols/weighted_staircase.h", {"weighted-staircase"}},
        {"protocols/include/atonlab/protocols/quest.h", {"quest"}},
        {"protocols/include/atonlab/protocols/adjustment.h", {"adjustment"}},
        {"protocols/include/atonlab/protocols/constant_stimuli.h", {"constant-stimuli"}},
        // The report's file formats (docs/analysis.md): report.json's "quest" and
        // "adjustment" objects and estimates.csv's "adjustment" rows are the
        // summaries' names, read by other tools; they do not name a procedure.
        {"analysis/src/report_data.cpp", {"quest", "adjustment"}},
    };
    std::vector<std::string> names;
    for (const p::ProcedureType* t : p::procedure_types()) names.emplace_back(t->name);
    ASSERT_FALSE(names.empty());

    std::vector<std::string> found;
    std::size_t scanned = 0;
    for (const char* dir : {"protocols", "analysis", "runner", "python", "bench", "present"}) {
        for (const auto& e : fs::recursive_directory_iterator(root / dir)) {
            const std::string ext = e.path().extension().string();
            if (!e.is_regular_file() || (ext != ".h" && ext != ".cpp")) continue;
            ++scanned;
            const std::string rel = fs::relative(e.path(), root).generic_string();
            std::ifstream in(e.path());
            const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
            for (const std::string& lit : string_literals(text)) {
                for (const std::string& name : names) {
                    // The literal is the name, or quotes it in a message.
                    if (lit != name && lit.find("\"" + name + "\"") == std::string::npos) continue;
                    const auto it = allowed.find(rel);
                    if (it != allowed.end() && it->second.count(name) != 0) continue;
                    found.push_back(rel + ": \"" + lit + "\"");
                }
            }
        }
    }
    EXPECT_GT(scanned, 100U) << "the scan found too few sources under " << root;
    std::string list;
    for (const std::string& f : found) list += "\n  " + f;
    EXPECT_TRUE(found.empty()) << "a procedure's name is spelled outside the registry (ask "
                                  "protocols::find_procedure_type or the kind's ProcedureType instead):"
                               << list;
}

TEST(ProcedureRegistry, TheArchitectureDocNamesTheFilesANewKindTouches) {
    // docs/architecture.md "How to add a procedure": its numbered steps name
    // the files outside tests and docs, at most 4, each an existing
    // procedure's counterpart (QUEST's is checked to exist).
    std::ifstream in(fs::path(ATONLAB_SOURCE_DIR) / "docs/architecture.md");
    const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t at = doc.find("## How to add a procedure");
    ASSERT_NE(at, std::string::npos);
    const std::size_t end = doc.find("\n## ", at + 1);
    const std::string section = doc.substr(at, end == std::string::npos ? std::string::npos : end - at);
    std::set<std::string> files;
    const std::regex code(R"(`((protocols|analysis|runner)/[A-Za-z0-9_/.]+\.(h|cpp))`)");
    for (auto m = std::sregex_iterator(section.begin(), section.end(), code); m != std::sregex_iterator(); ++m)
        files.insert((*m)[1].str());
    EXPECT_GE(files.size(), 1U);
    EXPECT_LE(files.size(), 4U) << "a new procedure should touch at most 4 files outside tests and docs";
    for (std::string f : files) {
        for (std::size_t at_name = f.find("NAME"); at_name != std::string::npos; at_name = f.find("NAME"))
            f.replace(at_name, 4, "quest");
        EXPECT_TRUE(fs::exists(fs::path(ATONLAB_SOURCE_DIR) / f)) << f;
    }
}

}  // namespace
