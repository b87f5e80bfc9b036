// What `check` stored of a session's clipped and out-of-gamut lights reaches
// the analyst (analysis/include/atonlab/analysis/display_losses.h;
// docs/analysis.md "Light lost at the display"): analyze reads the shares and
// the limits back from the session's displayability_json, summary.json gives
// per condition the largest share of its judged lights and whether it is over
// the limit, the notes say it in one line per affected condition, and a record
// from before the shares or the limits were stored says "not recorded" and
// nothing more.
//
// The records are written here, for an analytic case: a uniform disc light
// whose target luminance is k times the display's white is shown at white, so
// it loses (k − 1)/k of its light there (the same share over any window that
// holds the whole disc). The shares below are that fraction, not numbers the
// code gave.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

#include "../store/store_test_support.h"
#include "analysis_test_data.h"
#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/display_losses.h"
#include "atonlab/analysis/plots.h"
#include "atonlab/analysis/report.h"
#include "atonlab/analysis/study_analysis.h"
#include "atonlab/store/json.h"

namespace atonlab::analysis {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using store::test_support::file_bytes;
using store::test_support::TempDir;
namespace td = test_data;

/// The share of a uniform disc's light lost when its luminance, k × white, is shown at white.
double clipped_share(double k) {
    return k > 1.0 ? (k - 1.0) / k : 0.0;
}

Json light(const std::string& role, double white_k, double gamut_share = 0.0) {
    return Json{{"role", role},
                {"light", role},
                {"added_lux", 1e-6},
                {"white_loss_share", clipped_share(white_k)},
                {"gamut_loss_share", gamut_share}};
}

/// A displayability record as `atonlab run` stores it (docs/store.md), for
/// constant_stimuli_protocol's two conditions (level on the reference, 1.7 .. 2.3):
///  night-empirical:  the test at 4 × white (75 % lost) and the reference at 1.16 × white at the top
///                    (13.8 %), 0.5 × at the bottom (none);
///  night-perceptual: shown in keep-signal-colour; the test gives up 8 % to it and is not clipped.
/// `thresholds`: store the limits (as now) or not (a record from before them).
std::string record(bool thresholds) {
    const Json empirical{{"name", "night-empirical"},
                         {"displayable", true},
                         {"warnings", Json::array({"at max_level (2.3) the reference light \"reference\" is clipped"})},
                         {"ends",
                          {Json{{"level", 1.7},
                                {"out_of_gamut", "keep-luminance"},
                                {"lights", {light("test", 4.0), light("reference", 0.5)}}},
                           Json{{"level", 2.3},
                                {"out_of_gamut", "keep-luminance"},
                                {"lights", {light("test", 4.0), light("reference", 1.16)}}}}}};
    const Json perceptual{{"name", "night-perceptual"},
                          {"displayable", true},
                          {"warnings", Json::array()},
                          {"ends",
                           {Json{{"level", 1.7},
                                 {"out_of_gamut", "keep-signal-colour"},
                                 {"lights", Json::array({light("test", 0.9, 0.08)})}},
                            Json{{"level", 2.3},
                                 {"out_of_gamut", "keep-signal-colour"},
                                 {"lights", Json::array({light("test", 0.9, 0.08)})}}}}};
    Json j{{"display", {{"width_px", 320}, {"height_px", 180}, {"out_of_gamut", "keep-luminance"}}},
           {"window_radius_deg", 0.5}};
    if (thresholds) j["thresholds"] = Json{{"white_loss_warning_share", 0.01}, {"max_out_of_gamut_loss", 0.05}};
    j["displayable"] = true;
    j["allowed_undisplayable"] = false;
    j["conditions"] = {empirical, perceptual};
    j["presentation"] = nullptr;
    return store::dump_json(j);
}

/// The study analysed and written: summary.json parsed, report.html's text, the notes.
struct Written {
    nlohmann::json summary;
    std::string html;
    std::vector<std::string> notes;
};

Written analyse(const fs::path& dir, const std::string& displayability) {
    td::SimObserver obs = td::sim("A", 2.0, 0.1);
    obs.displayability_json = displayability;
    td::run_simulated(dir / "s.db", td::constant_stimuli_protocol(2), obs);
    const Dataset d = read_study(dir / "s.db");
    AnalysisOptions o;
    o.bootstrap = 0;
    const StudyResults r = analyze_study(d, o);
    PlotResult plots;  // no figures: this test is about the words and numbers
    ReportContext ctx;
    ctx.data = &d;
    ctx.results = &r;
    ctx.plots = &plots;
    ctx.software_version = "test";
    fs::create_directories(dir / "out");
    write_report(dir / "out", ctx);
    return {store::parse_json(file_bytes(dir / "out/summary.json"), "summary.json"),
            file_bytes(dir / "out/report.html"), r.warnings};
}

std::size_t count_containing(const std::vector<std::string>& lines, const std::string& part) {
    std::size_t n = 0;
    for (const std::string& l : lines) n += l.find(part) != std::string::npos;
    return n;
}

TEST(AnalysisDisplayLosses, SharesAndLimitsReachSummaryNotesAndReport) {
    TempDir dir;
    const Written w = analyse(dir.path(), record(true));
    const nlohmann::json& s = w.summary.at("sessions").at(0);
    EXPECT_EQ(store::number_at(s, "/display_thresholds/white_loss_warning_share"), 0.01);
    EXPECT_EQ(store::number_at(s, "/display_thresholds/max_out_of_gamut_loss"), 0.05);
    ASSERT_EQ(store::array_at(s, "/display_losses").size(), 2u);

    // night-empirical: the largest of its lights is the test's 3/4, at either end (the first kept).
    const nlohmann::json& e = s.at("display_losses").at(0);
    EXPECT_EQ(store::string_at(e, "/condition"), "night-empirical");
    EXPECT_DOUBLE_EQ(store::number_at(e, "/white_loss/share").value_or(-1.0), 0.75);
    EXPECT_EQ(store::string_at(e, "/white_loss/role"), "test");
    EXPECT_EQ(store::boolean_at(e, "/white_loss_over_warning"), true);
    EXPECT_DOUBLE_EQ(store::number_at(e, "/gamut_loss/share").value_or(-1.0), 0.0);
    EXPECT_EQ(store::boolean_at(e, "/gamut_loss_over_limit"), false);
    EXPECT_EQ(store::array_at(e, "/warnings").size(), 1u);
    // night-perceptual: 8 % to keep-signal-colour, over R5's 5 %; nothing at white.
    const nlohmann::json& p = s.at("display_losses").at(1);
    EXPECT_DOUBLE_EQ(store::number_at(p, "/white_loss/share").value_or(-1.0), 0.0);
    EXPECT_EQ(store::boolean_at(p, "/white_loss_over_warning"), false);
    EXPECT_DOUBLE_EQ(store::number_at(p, "/gamut_loss/share").value_or(-1.0), 0.08);
    EXPECT_EQ(store::string_at(p, "/out_of_gamut"), "keep-signal-colour");
    EXPECT_EQ(store::boolean_at(p, "/gamut_loss_over_limit"), true);

    // One note per affected condition, with the share at one decimal.
    EXPECT_EQ(count_containing(w.notes,
                               "condition \"night-empirical\": its test light \"test\" loses 75.0 % of "
                               "its light at the display's white at level 1.7 (check warns above 1 %)"),
              1u);
    EXPECT_EQ(count_containing(w.notes,
                               "condition \"night-perceptual\": its test light \"test\" gives up 8.0 % of "
                               "its light to display.out_of_gamut = \"keep-signal-colour\""),
              1u);
    EXPECT_EQ(count_containing(w.notes, "(more than display.max_out_of_gamut_loss, 5 %)"), 1u);
    // summary.json's warnings are those notes; the report's table gives the shares.
    std::size_t in_summary = 0;
    for (const nlohmann::json& n : store::array_at(w.summary, "/warnings"))
        in_summary += n.is_string() && n.get<std::string>().find("loses 75.0 %") != std::string::npos;
    EXPECT_EQ(in_summary, 1u);
    EXPECT_NE(w.html.find("<h3 id=\"display-losses\">Light lost at the display</h3>"), std::string::npos);
    EXPECT_NE(w.html.find("75.0 % (test light &quot;test&quot;, level 1.7)"), std::string::npos);
    EXPECT_NE(w.html.find("8.0 % (test light &quot;test&quot;, level 1.7)"), std::string::npos);
}

// The quick start's case: the reference alone clipped, 1.16 × white: 13.8 % (0.16/1.16 = 0.1379).
TEST(AnalysisDisplayLosses, TheLargestShareNamesItsLightAndLevel) {
    SessionInfo s;
    s.white_loss_warning_share = 0.01;
    s.max_out_of_gamut_loss = 0.05;
    DisplayLoss c;
    c.condition = "ref-high";
    c.white = LightLoss{clipped_share(1.16), "reference", "ref", 1.0};
    c.gamut = LightLoss{0.0, "reference", "ref", 1.0};
    s.display_losses = {c};
    const std::vector<std::string> said = display_loss_sentences(s);
    ASSERT_EQ(said.size(), 1u);
    EXPECT_EQ(said[0],
              "condition \"ref-high\": its reference light \"ref\" loses 13.8 % of its light at the display's white "
              "at level 1 (check warns above 1 %)");
    // At the warning share itself (W1 warns above it): said nowhere, and not over.
    s.display_losses[0].white->share = 0.01;
    EXPECT_TRUE(display_loss_sentences(s).empty());
    EXPECT_EQ(white_over_warning(s, s.display_losses[0]), false);
    EXPECT_EQ(loss_text(std::nullopt), "not recorded");
    EXPECT_EQ(loss_text(LightLoss{0.0001, "test", "t", 2.0}), "none");
}

// A record from before the limits were stored: the shares are given, judged by
// nothing; before the shares too: "not recorded", and no note either way.
TEST(AnalysisDisplayLosses, OlderRecordsSayNotRecordedAndNothingMore) {
    TempDir dir;
    const Written w = analyse(dir.path(), record(false));
    const nlohmann::json& s = w.summary.at("sessions").at(0);
    EXPECT_TRUE(s.at("display_thresholds").at("white_loss_warning_share").is_null());
    EXPECT_TRUE(s.at("display_thresholds").at("max_out_of_gamut_loss").is_null());
    EXPECT_DOUBLE_EQ(store::number_at(s, "/display_losses/0/white_loss/share").value_or(-1.0), 0.75);
    EXPECT_TRUE(s.at("display_losses").at(0).at("white_loss_over_warning").is_null());
    EXPECT_TRUE(s.at("display_losses").at(1).at("gamut_loss_over_limit").is_null());
    EXPECT_EQ(count_containing(w.notes, "at the display's white"), 0u);
    EXPECT_EQ(count_containing(w.notes, "max_out_of_gamut_loss"), 0u);
    EXPECT_NE(w.html.find("<td class=\"num\">not recorded</td>"), std::string::npos);

    // No shares at all (the record of a session before issue 44): every loss not recorded.
    nlohmann::json old = store::parse_json(record(false), "record");
    for (nlohmann::json& c : old.at("conditions"))
        for (nlohmann::json& e : c.at("ends"))
            for (nlohmann::json& l : e.at("lights")) {
                l.erase("white_loss_share");
                l.erase("gamut_loss_share");
            }
    TempDir older;
    const Written o = analyse(older.path(), store::dump_json(old));
    for (const nlohmann::json& c : o.summary.at("sessions").at(0).at("display_losses")) {
        EXPECT_TRUE(c.at("white_loss").is_null()) << c.dump();
        EXPECT_TRUE(c.at("gamut_loss").is_null()) << c.dump();
    }
    EXPECT_EQ(count_containing(o.notes, "at the display's white"), 0u);
    EXPECT_NE(o.html.find("<td>not recorded</td>"), std::string::npos);
}

}  // namespace
}  // namespace atonlab::analysis
