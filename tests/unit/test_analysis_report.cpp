// `atonlab analyze`'s outputs (analysis/include/atonlab/analysis/report.h,
// plots.h, study_analysis.h): degenerate data is flagged with a reason and
// never becomes NaN; summary.json is valid JSON; report.html is well formed,
// self-contained and lists only figures that exist; a missing gnuplot still
// gives a report; a simulated observer's known PSE is recovered.
#include <gtest/gtest.h>

#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <set>

#include "../store/store_test_support.h"
#include "analysis_test_data.h"
#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/plots.h"
#include "atonlab/analysis/report.h"
#include "atonlab/analysis/study_analysis.h"
#include "atonlab/display/display_model.h"
#include "atonlab/display/fit_json.h"
#include "atonlab/store/json.h"
#include "../support/skip.h"

namespace atonlab::analysis {
namespace {

namespace fs = std::filesystem;
using store::test_support::file_bytes;
using store::test_support::TempDir;
namespace td = test_data;

Trial trial(const std::string& condition, double level, std::optional<bool> outcome, const std::string& obs = "P") {
    Trial t;
    t.source = "synthetic";
    t.session = "synthetic#" + obs;
    t.observer = obs;
    t.condition = condition;
    t.level = level;
    t.outcome = outcome;
    t.response = outcome ? (*outcome ? "yes" : "no") : "timeout";
    t.task = protocols::Task::YesNo;
    t.level_on = "test";
    t.level_key = "light.flash.intensity_cd";
    return t;
}

/// A dataset with one degenerate condition each, plus a condition of the
/// protocol that has no trials at all.
Dataset degenerate() {
    Dataset d;
    d.sources = {"synthetic"};
    SessionInfo s;
    s.key = "synthetic#P";
    s.source = "synthetic";
    s.observer = "P";
    s.protocol_conditions = {"all-yes", "all-no", "one-level", "one-trial", "no-trials", "no-answers"};
    d.sessions.push_back(s);
    for (double l : {1.0, 2.0, 3.0})
        for (int i = 0; i < 5; ++i) d.trials.push_back(trial("all-yes", l, true));
    for (double l : {1.0, 2.0, 3.0})
        for (int i = 0; i < 5; ++i) d.trials.push_back(trial("all-no", l, false));
    for (int i = 0; i < 10; ++i) d.trials.push_back(trial("one-level", 2.0, i % 2 == 0));
    d.trials.push_back(trial("one-trial", 2.0, true));
    for (int i = 0; i < 3; ++i) d.trials.push_back(trial("no-answers", 2.0, std::nullopt));
    for (std::size_t i = 0; i < d.trials.size(); ++i) d.trials[i].trial_index = static_cast<std::int64_t>(i);
    return d;
}

/// The first word that spells a non-finite number ("nan", "inf", "infinity", any case), or "".
std::string non_finite_word(const std::string& text) {
    std::string word;
    for (std::size_t i = 0; i <= text.size(); ++i) {
        const bool letter = i < text.size() && std::isalpha(static_cast<unsigned char>(text[i]));
        if (letter) {
            word += static_cast<char>(std::tolower(static_cast<unsigned char>(text[i])));
            continue;
        }
        if (word == "nan" || word == "inf" || word == "infinity") return word;
        word.clear();
    }
    return {};
}

TEST(AnalysisReport, DegenerateConditionsAreFlaggedWithReasonsNeverNaN) {
    const Dataset d = degenerate();
    AnalysisOptions o;
    o.bootstrap = 50;
    const StudyResults r = analyze_study(d, o);
    ASSERT_EQ(r.conditions.size(), 6u);
    for (const std::string name : {"all-yes", "all-no", "one-level", "one-trial", "no-trials", "no-answers"}) {
        const GroupResult* g = r.main_group(name);
        ASSERT_NE(g, nullptr) << name;
        EXPECT_FALSE(g->headline.reliable) << name;
        EXPECT_FALSE(g->headline.reason.empty()) << name;
        if (g->headline.value) {
            EXPECT_TRUE(std::isfinite(*g->headline.value)) << name;
        }
    }
    EXPECT_EQ(r.main_group("no-trials")->n_trials, 0);

    TempDir dir;
    PlotResult plots;  // no figures: this test is about the numbers
    ReportContext ctx;
    ctx.data = &d;
    ctx.results = &r;
    ctx.plots = &plots;
    ctx.software_version = "test";
    write_report(dir.path(), ctx);
    const std::string json = file_bytes(dir / "summary.json");
    const std::string csv = file_bytes(dir / "fits.csv");
    const std::string html = file_bytes(dir / "report.html");
    for (const std::string* text : {&json, &csv, &html}) EXPECT_EQ(non_finite_word(*text), "");
    // Valid JSON (the store's parser refuses anything else), nulls with reasons.
    const nlohmann::json j = store::parse_json(json, "summary.json");
    const std::size_t n = store::array_at(j, "/conditions").size();
    ASSERT_EQ(n, 6u);
    for (std::size_t i = 0; i < n; ++i) {
        const std::string at = fmt::format("/conditions/{}/groups/0/headline", i);
        const auto reason = store::string_at(j, at + "/reason");
        ASSERT_TRUE(reason.has_value());
        EXPECT_FALSE(reason->empty()) << at;
        EXPECT_EQ(store::boolean_at(j, at + "/reliable"), std::optional<bool>(false)) << at;
        const std::string cond = *store::string_at(j, fmt::format("/conditions/{}/condition", i));
        if (cond == "no-trials" || cond == "one-trial" || cond == "no-answers") {
            EXPECT_FALSE(store::number_at(j, at + "/value").has_value()) << cond << ": value should be null";
        }
        EXPECT_NE(html.find(fmt::format(">{}<", cond)), std::string::npos) << cond;
    }
    // fits.csv carries the reasons: every headline row has reliable = 0 and a non-empty reason.
    std::istringstream lines(csv);
    std::string line;
    std::getline(lines, line);
    int headlines = 0;
    while (std::getline(lines, line)) {
        if (line.find(",headline,") == std::string::npos) continue;
        ++headlines;
        EXPECT_NE(line.find(",0,"), std::string::npos) << line;
    }
    EXPECT_EQ(headlines, 6);
}

/// The tags of an HTML document balance (void elements aside), and nothing is
/// loaded from elsewhere.
void expect_well_formed_and_self_contained(const std::string& html) {
    static const std::set<std::string> kVoid{"meta", "img", "br", "hr", "link", "input"};
    std::vector<std::string> stack;
    // A plain scan (std::regex recurses per character and overflows on the base64 images).
    for (std::size_t at = html.find('<'); at != std::string::npos; at = html.find('<', at + 1)) {
        if (html.compare(at, 2, "<!") == 0) continue;  // the doctype
        const std::size_t end = html.find('>', at);
        ASSERT_NE(end, std::string::npos) << "a tag that never ends at " << at;
        const bool closing = html[at + 1] == '/';
        std::size_t b = at + (closing ? 2 : 1), e = b;
        while (e < end && std::isalnum(static_cast<unsigned char>(html[e]))) ++e;
        const std::string name = html.substr(b, e - b);
        ASSERT_FALSE(name.empty()) << "a '<' that starts no tag at " << at << ": " << html.substr(at, 40);
        if (kVoid.count(name) || html[end - 1] == '/') continue;
        if (closing) {
            ASSERT_FALSE(stack.empty()) << "</" << name << "> closes nothing";
            ASSERT_EQ(stack.back(), name) << "</" << name << "> closes <" << stack.back() << ">";
            stack.pop_back();
        } else {
            stack.push_back(name);
        }
    }
    EXPECT_TRUE(stack.empty()) << "unclosed <" << (stack.empty() ? "" : stack.back()) << ">";
    // Every row of a table has as many cells as its header row.
    for (std::size_t t = html.find("<table>"); t != std::string::npos; t = html.find("<table>", t + 1)) {
        const std::string table = html.substr(t, html.find("</table>", t) - t);
        int header = -1;
        for (std::size_t r = table.find("<tr>"); r != std::string::npos; r = table.find("<tr>", r + 1)) {
            const std::string row = table.substr(r, table.find("</tr>", r) - r);
            int cells = 0;
            for (std::size_t c = row.find("<t"); c != std::string::npos; c = row.find("<t", c + 1))
                cells += row.compare(c, 3, "<td") == 0 || row.compare(c, 3, "<th") == 0 ? 1 : 0;
            if (header < 0) header = cells;
            EXPECT_EQ(cells, header) << row.substr(0, 200);
        }
    }
    EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
    for (const char* bad :
         {"src=\"http", "href=\"http", "src=\"//", "href=\"//", "<script", "<link", "@import", "url("})
        EXPECT_EQ(html.find(bad), std::string::npos) << bad;
}

bool have_gnuplot() {
    return std::system("gnuplot --version > /dev/null 2>&1") == 0;
}

TEST(AnalysisReport, RecoversAKnownPseAndWritesAWellFormedSelfContainedReport) {
    TempDir dir;
    // 2 conditions x 7 levels x 20 repetitions of a simulated observer with PSE 10^1.95 cd.
    const double mu = 1.95, sigma = 0.12;
    td::run_simulated(dir / "s.db", td::constant_stimuli_protocol(20), td::sim("A", mu, sigma));
    // A second observer's staircases (another condition): the report's track tables and figures.
    td::run_simulated(dir / "s.db", td::staircase_protocol(), td::sim("B", 2.0, 0.1, 5));
    const Dataset d = read_study(dir / "s.db");
    AnalysisOptions o;
    o.bootstrap = 200;
    const StudyResults r = analyze_study(d, o);
    for (const std::string name : {"night-empirical", "night-perceptual"}) {
        const GroupResult* g = r.main_group(name);
        ASSERT_NE(g, nullptr);
        ASSERT_TRUE(g->headline.value && g->headline.ci) << g->headline.reason;
        EXPECT_TRUE(g->headline.reliable) << g->headline.reason;
        // 140 trials around the PSE: the estimate lies within 0.05 log10 of it, the CI holds it.
        EXPECT_NEAR(*g->headline.value, mu, 0.05);
        EXPECT_TRUE(g->headline.ci->contains(mu)) << g->headline.ci->lower << " .. " << g->headline.ci->upper;
        // Brightness enhancement: PSE - log10(100 cd).
        ASSERT_TRUE(g->match_ratio && g->match_ratio->value);
        EXPECT_DOUBLE_EQ(*g->match_ratio->value, *g->headline.value - 2.0);
    }

    if (!have_gnuplot()) ATONLAB_SKIP_MISSING_TOOL() << "gnuplot is not installed (Debian package gnuplot-nox)";
    const fs::path out = dir / "out";
    fs::create_directories(out);
    const PlotResult plots = make_figures(out, d, r);
    EXPECT_TRUE(plots.problems.empty()) << plots.problems.front();
    std::set<std::string> kinds;
    for (const Figure& f : plots.figures) kinds.insert(f.kind);
    EXPECT_TRUE(kinds.count("psychometric") && kinds.count("pse") && kinds.count("enhancement") &&
                kinds.count("timing") && kinds.count("tracks"));
    ReportContext ctx;
    ctx.data = &d;
    ctx.results = &r;
    ctx.plots = &plots;
    ctx.software_version = "test";
    write_report(out, ctx);
    const std::string html = file_bytes(out / "report.html");
    expect_well_formed_and_self_contained(html);
    // Every figure summary.json lists exists, is non-empty, and is embedded in the report.
    const nlohmann::json j = store::parse_json(file_bytes(out / "summary.json"), "summary.json");
    const std::size_t n = store::array_at(j, "/figures").size();
    EXPECT_EQ(n, plots.figures.size());
    for (std::size_t i = 0; i < n; ++i) {
        for (const char* key : {"png", "svg"}) {
            const auto rel = store::string_at(j, fmt::format("/figures/{}/{}", i, key));
            ASSERT_TRUE(rel.has_value());
            std::error_code ec;
            EXPECT_GT(fs::file_size(out / *rel, ec), 0u) << *rel;
            EXPECT_FALSE(ec) << *rel;
        }
        const std::string png = file_bytes(out / *store::string_at(j, fmt::format("/figures/{}/png", i)));
        EXPECT_EQ(png.substr(1, 3), "PNG");
        EXPECT_NE(html.find(base64(png).substr(0, 200)), std::string::npos) << "figure " << i << " not embedded";
    }
}

/// Compares the number at `at` with `want` bit for bit (a finite double must
/// read back as the same double); absent or non-finite must be null.
/// Returns whether a finite number was compared.
bool expect_same_bits(const nlohmann::json& j, const std::string& at, std::optional<double> want) {
    const nlohmann::json* v = store::json_at(j, at);
    if (!v) {
        ADD_FAILURE() << at << " is missing";
        return false;
    }
    if (!want || !std::isfinite(*want)) {
        EXPECT_TRUE(v->is_null()) << at << " should be null, is " << v->dump();
        return false;
    }
    EXPECT_TRUE(v->is_number()) << at << " is " << v->dump();
    if (!v->is_number()) return false;
    EXPECT_EQ(std::bit_cast<std::uint64_t>(v->get<double>()), std::bit_cast<std::uint64_t>(*want))
        << at << ": " << fmt::format("{} read back as {}", *want, v->get<double>());
    return true;
}

TEST(AnalysisReport, SummaryJsonNumbersReadBackBitForBit) {
    TempDir dir;
    td::run_simulated(dir / "s.db", td::constant_stimuli_protocol(10), td::sim("A", 1.95, 0.12));
    td::run_simulated(dir / "s.db", td::staircase_protocol(), td::sim("B", 2.0, 0.1, 5));
    const Dataset d = read_study(dir / "s.db");
    AnalysisOptions o;
    o.bootstrap = 40;
    const StudyResults r = analyze_study(d, o);
    const PlotResult plots;
    ReportContext ctx;
    ctx.data = &d;
    ctx.results = &r;
    ctx.plots = &plots;
    ctx.software_version = "test";
    write_summary_json(dir / "summary.json", ctx);
    const nlohmann::json j = store::parse_json(file_bytes(dir / "summary.json"), "summary.json");
    int compared = 0;
    auto same = [&](const std::string& at, std::optional<double> want) { compared += expect_same_bits(j, at, want); };
    auto same_interval = [&](const std::string& at, const std::optional<Interval>& ci) {
        if (!ci) return same(at, std::nullopt);
        same(at + "/0", ci->lower);
        same(at + "/1", ci->upper);
    };
    ASSERT_EQ(store::array_at(j, "/conditions").size(), r.conditions.size());
    for (std::size_t i = 0; i < r.conditions.size(); ++i) {
        const ConditionInfo& c = r.conditions[i];
        const std::string cat = fmt::format("/conditions/{}", i);
        same(cat + "/guess_rate", c.guess_rate);
        same(cat + "/target_p", c.target_p);
        same(cat + "/adaptation_cd_m2", c.adaptation_cd_m2);
        same(cat + "/test_intensity_cd", c.test_intensity_cd);
        std::size_t k = 0;
        for (const GroupResult& g : r.groups) {
            if (g.condition != c.condition) continue;
            const std::string at = fmt::format("{}/groups/{}", cat, k++);
            same(at + "/headline/value", g.headline.value);
            same_interval(at + "/headline/ci", g.headline.ci);
            same(at + "/reversal_mean", g.reversal_mean);
            same(at + "/posterior_mean", g.posterior_mean);
            for (std::size_t l = 0; l < g.counts.size(); ++l)
                same(fmt::format("{}/counts/{}/level", at, l), g.counts[l].level);
            if (g.fit && g.fit->estimate) {
                const PsychometricEstimate& e = *g.fit->estimate;
                same(at + "/psychometric/threshold_proportion", g.threshold_proportion);
                for (const auto& [key, want] : {std::pair{"alpha", e.params.alpha},
                                                {"beta", e.params.beta},
                                                {"gamma", e.params.gamma},
                                                {"lambda", e.params.lambda},
                                                {"threshold", e.threshold},
                                                {"psi_at_threshold", e.psi_at_threshold},
                                                {"slope", e.slope},
                                                {"width", e.width},
                                                {"log_likelihood", e.log_likelihood},
                                                {"deviance", e.deviance}})
                    same(at + "/psychometric/" + key, want);
            }
            if (g.bootstrap) {
                const PsychometricBootstrap& b = *g.bootstrap;
                same_interval(at + "/psychometric/bootstrap/ci/threshold", b.threshold);
                same_interval(at + "/psychometric/bootstrap/ci/slope", b.slope);
                same(at + "/psychometric/bootstrap/goodness_of_fit/deviance", b.goodness_of_fit.deviance);
                same(at + "/psychometric/bootstrap/goodness_of_fit/p_value", b.goodness_of_fit.p_value);
                same(at + "/psychometric/bootstrap/goodness_of_fit/p_value_chi2", b.goodness_of_fit.p_value_chi2);
            }
            for (std::size_t t = 0; t < g.tracks.size(); ++t)
                if (const auto& rev = g.tracks[t].reversals) {
                    same(fmt::format("{}/tracks/{}/reversals/mean", at, t), rev->mean);
                    same(fmt::format("{}/tracks/{}/reversals/sd", at, t), rev->sd);
                }
            if (g.match_ratio) same(at + "/match_ratio/log10_ratio", g.match_ratio->value);
        }
    }
    // Fits, bootstrap intervals and staircase means: many numbers with all 17 digits.
    EXPECT_GT(compared, 50);
}

TEST(AnalysisReport, WithoutGnuplotTheReportSaysSoAndIsStillWritten) {
    TempDir dir;
    const Dataset d = degenerate();
    AnalysisOptions o;
    o.bootstrap = 0;
    const StudyResults r = analyze_study(d, o);
    PlotOptions po;
    po.gnuplot = (dir / "no-such-gnuplot").string();
    const PlotResult plots = make_figures(dir.path(), d, r, po);
    EXPECT_TRUE(plots.gnuplot_missing);
    EXPECT_TRUE(plots.figures.empty());
    ASSERT_EQ(plots.problems.size(), 1u);
    EXPECT_NE(plots.problems[0].find("gnuplot-nox"), std::string::npos) << plots.problems[0];
    ReportContext ctx;
    ctx.data = &d;
    ctx.results = &r;
    ctx.plots = &plots;
    write_report(dir.path(), ctx);
    const std::string html = file_bytes(dir / "report.html");
    EXPECT_NE(html.find("gnuplot could not be started"), std::string::npos);
    expect_well_formed_and_self_contained(html);
}

TEST(AnalysisReport, ConditionFileNamesAreUniqueAndTheHashOnlyWhereSlugsCollide) {
    // Expected hashes: printf 'a<b' | sha256sum, printf 'a>b' | sha256sum (first 8 hex digits).
    const auto slugs = condition_slugs(std::vector<std::string>{"a<b", "a>b", "plain", "x y", "night-empirical"});
    EXPECT_EQ(slugs.at("a<b"), "a_b-4a826aac");
    EXPECT_EQ(slugs.at("a>b"), "a_b-998a5be8");
    EXPECT_EQ(slugs.at("plain"), "plain");
    EXPECT_EQ(slugs.at("x y"), "x_y") << "no collision: the slug alone";
    EXPECT_EQ(slugs.at("night-empirical"), "night-empirical");
    // A name keeps its file name whatever else the study has.
    EXPECT_EQ(condition_slugs(std::vector<std::string>{"a<b", "a>b", "other"}).at("a<b"), "a_b-4a826aac");
}

TEST(AnalysisReport, ConditionsWhoseNamesShareASlugGetTheirOwnFigures) {
    // Two yes-no conditions, "a<b" and "a>b" (both "a_b" as a file name), with
    // different data: each must get its own psychometric figure.
    Dataset d;
    d.sources = {"synthetic"};
    SessionInfo s;
    s.key = "synthetic#P";
    s.source = "synthetic";
    s.observer = "P";
    s.protocol_conditions = {"a<b", "a>b"};
    d.sessions.push_back(s);
    for (double l : {1.0, 2.0, 3.0, 4.0})
        for (int i = 0; i < 8; ++i) d.trials.push_back(trial("a<b", l, i < 2 * l));
    for (double l : {6.0, 7.0, 8.0, 9.0})
        for (int i = 0; i < 8; ++i) d.trials.push_back(trial("a>b", l, i < 2 * (l - 5.0)));
    for (std::size_t i = 0; i < d.trials.size(); ++i) d.trials[i].trial_index = static_cast<std::int64_t>(i);
    AnalysisOptions o;
    o.bootstrap = 0;
    const StudyResults r = analyze_study(d, o);
    if (!have_gnuplot()) ATONLAB_SKIP_MISSING_TOOL() << "gnuplot is not installed (Debian package gnuplot-nox)";
    TempDir dir;
    const PlotResult plots = make_figures(dir.path(), d, r);
    std::map<std::string, const Figure*> psychometric;
    for (const Figure& f : plots.figures)
        if (f.kind == "psychometric") psychometric[f.condition] = &f;
    ASSERT_EQ(psychometric.size(), 2u);
    EXPECT_EQ(psychometric.at("a<b")->png, fs::path("figures/psychometric-a_b-4a826aac.png"));
    EXPECT_EQ(psychometric.at("a>b")->png, fs::path("figures/psychometric-a_b-998a5be8.png"));
    EXPECT_NE(file_bytes(dir / psychometric.at("a<b")->png.c_str()), file_bytes(dir / psychometric.at("a>b")->png.c_str()))
        << "each figure draws its own condition's data";
}

TEST(AnalysisReport, Base64MatchesRfc4648Vectors) {
    // RFC 4648 §10 test vectors.
    EXPECT_EQ(base64(""), "");
    EXPECT_EQ(base64("f"), "Zg==");
    EXPECT_EQ(base64("fo"), "Zm8=");
    EXPECT_EQ(base64("foo"), "Zm9v");
    EXPECT_EQ(base64("foob"), "Zm9vYg==");
    EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
    EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
}

TEST(AnalysisReport, NominalDisplayModelCurveIsTheSrgbCurve) {
    // The runner's nominal model: three sRGB channels sharing black 0.1 and white 100 cd/m2 by Rec.709 weights.
    const std::string fit =
        R"({"model":"nominal","peak_cd_m2":100,"black_cd_m2":0.1,"bits":8,"dither":true,"channels":[)"
        R"({"encoding":"srgb","black_cd_m2":0.021264,"white_cd_m2":21.264},)"
        R"({"encoding":"srgb","black_cd_m2":0.071517,"white_cd_m2":71.517},)"
        R"({"encoding":"srgb","black_cd_m2":0.007219,"white_cd_m2":7.219}]})";
    // IEC 61966-2-1: V = 0.5 decodes to ((0.5 + 0.055) / 1.055)^2.4 = 0.21404.
    const double expect = 0.1 + (100.0 - 0.1) * std::pow(0.555 / 1.055, 2.4);
    EXPECT_NEAR(*model_grey_luminance_cd_m2(fit, 0.5), expect, 1e-9);
    EXPECT_NEAR(*model_grey_luminance_cd_m2(fit, 0.0), 0.1, 1e-12);
    EXPECT_NEAR(*model_grey_luminance_cd_m2(fit, 1.0), 100.0, 1e-9);
    EXPECT_FALSE(model_grey_luminance_cd_m2(R"({"channels":[{"transfer":"lut"}]})", 0.5).has_value());
    // A measured GOG model (docs/calibration.md "fit_json"), stored with the key's old name "transfer":
    // L = sum over channels of a + (b + k V)^gamma.
    const std::string gog = R"({"model":"gog","display":{"peak_cd_m2":100,"black_cd_m2":0.1,"channels":[)"
                            R"({"channel":"red","transfer":"gog","a":0.03,"b":0.02,"k":2.9,"gamma":2.2},)"
                            R"({"channel":"green","transfer":"gog","a":0.05,"b":-0.01,"k":5.0,"gamma":2.4},)"
                            R"({"channel":"blue","transfer":"gog","a":0.02,"b":0.0,"k":1.5,"gamma":2.0}]}})";
    const double v = 0.6;
    const double gog_expect =
        0.03 + std::pow(0.02 + 2.9 * v, 2.2) + 0.05 + std::pow(-0.01 + 5.0 * v, 2.4) + 0.02 + std::pow(1.5 * v, 2.0);
    EXPECT_NEAR(*model_grey_luminance_cd_m2(gog, v), gog_expect, 1e-12 * gog_expect);
    // Where b + k V <= 0 the channel emits its offset a alone.
    EXPECT_NEAR(*model_grey_luminance_cd_m2(gog, 0.0), 0.03 + std::pow(0.02, 2.2) + 0.05 + 0.02, 1e-12);
    EXPECT_FALSE(model_grey_luminance_cd_m2("not json", 0.5).has_value());
}

TEST(AnalysisReport, LutDisplayCurveIsTheModelsLuminanceAtTheLutPoints) {
    // A measured-LUT display as the runner records it (display::nominal_fit_json). Its
    // knots lie on 8-bit codes (k/255 for k = 0, 51, ..., 255), so at each the plotted
    // grey curve must be the sum of the three channels' tabulated cd/m² (PCHIP passes
    // through its knots) and what the model says the screen emits for that code.
    const std::vector<double> drives = {0.0, 51.0 / 255.0, 102.0 / 255.0, 153.0 / 255.0, 204.0 / 255.0, 1.0};
    const std::array<std::vector<double>, 3> cd_m2 = {{{0.03, 0.9, 3.7, 8.8, 14.1, 21.2},
                                                       {0.09, 2.6, 12.4, 29.0, 48.8, 71.6},
                                                       {0.01, 0.3, 1.2, 2.9, 4.8, 7.3}}};
    std::array<std::vector<display::LutPoint>, 3> lut;
    for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < drives.size(); ++i) lut[c].push_back({drives[i], cd_m2[c][i]});
    const display::DisplayModel model = display::DisplayModel::lut(lut, "booth-lut");
    const std::string fit = display::nominal_fit_json(model, display::EncodeSettings{});
    for (std::size_t i = 0; i < drives.size(); ++i) {
        const double tabulated = cd_m2[0][i] + cd_m2[1][i] + cd_m2[2][i];
        const auto plotted = model_grey_luminance_cd_m2(fit, drives[i]);
        ASSERT_TRUE(plotted.has_value()) << fit;
        EXPECT_NEAR(*plotted, tabulated, 1e-12 * tabulated) << "V = " << drives[i];
        const int code = static_cast<int>(std::lround(drives[i] * 255.0));
        EXPECT_NEAR(*plotted, display::displayed_luminance_cd_m2(model, glm::ivec3(code), 8), 1e-12 * tabulated);
    }
    // Between knots the curve is the model's interpolation, not a straight line.
    const double mid = 0.5 * (drives[1] + drives[2]);
    double model_mid = 0.0;
    for (int c = 0; c < 3; ++c) model_mid += model.channel_luminance_cd_m2(c, mid);
    EXPECT_EQ(*model_grey_luminance_cd_m2(fit, mid), model_mid);
}

}  // namespace
}  // namespace atonlab::analysis
