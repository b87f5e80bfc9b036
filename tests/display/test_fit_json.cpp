// fit_json (display/fit_json.h, docs/calibration.md "fit_json"): the display model
// written once and read back bit for bit, for every display encoding.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "atonlab/common/input_error.h"
#include "atonlab/display/fit_json.h"
#include "input_error.h"

namespace atonlab::display {
namespace {

void expect_same_model(const DisplayModel& a, const DisplayModel& b) {
    EXPECT_EQ(a.peak_cd_m2, b.peak_cd_m2);
    EXPECT_EQ(a.black_cd_m2, b.black_cd_m2);
    for (std::size_t c = 0; c < 3; ++c) {
        const ChannelEncoding& x = a.channels[c];
        const ChannelEncoding& y = b.channels[c];
        EXPECT_EQ(x.encoding, y.encoding) << c;
        EXPECT_EQ(x.parameter, y.parameter) << c;  // gog's a, b, k, gamma; pq's weight
        if (x.follows("srgb") || x.follows("pq")) {
            EXPECT_EQ(x.black_cd_m2, y.black_cd_m2);
            EXPECT_EQ(x.white_cd_m2, y.white_cd_m2);
        }
        ASSERT_EQ(x.lut.size(), y.lut.size());
        for (std::size_t i = 0; i < x.lut.size(); ++i) {
            EXPECT_EQ(x.lut[i].drive, y.lut[i].drive);
            EXPECT_EQ(x.lut[i].cd_m2, y.lut[i].cd_m2);
        }
    }
}

TEST(FitJson, NominalModelsRoundTripBitForBit) {
    const std::array<std::vector<LutPoint>, 3> lut = {{{{0.0, 0.031}, {0.3, 2.0 / 3.0}, {1.0, 21.3}},
                                                       {{0.0, 0.07}, {0.5, 17.1}, {1.0, 71.9}},
                                                       {{0.0, 0.01}, {0.7, 3.3}, {1.0, 7.1}}}};
    const std::array<GogParams, 3> gog = {{{0.03, 0.02, 2.9, 2.2}, {0.05, -0.01, 5.0, 2.4}, {0.02, 0.0, 1.5, 2.0}}};
    for (const DisplayModel& m : {DisplayModel::srgb(100.0 / 3.0, 0.1), DisplayModel::pq(1000.0, 0.005),
                                  DisplayModel::gog(gog), DisplayModel::lut(lut)}) {
        SCOPED_TRACE(m.name);
        const std::string text = nominal_fit_json(m, EncodeSettings{10, Dither::none, 7});
        EXPECT_EQ(fit_json_model(text), "nominal");
        expect_same_model(m, display_model_from_fit_json(text, m.name));
    }
}

TEST(FitJson, NominalRowHoldsBitsDitherAndEveryChannelsRange) {
    const DisplayModel m = DisplayModel::srgb(100.0, 0.1);
    const std::string text = nominal_fit_json(m, EncodeSettings{8, Dither::spatiotemporal, 0});
    EXPECT_NE(text.find(R"("bits":8,"dither":true)"), std::string::npos) << text;
    EXPECT_NE(text.find(R"("channel":"green","encoding":"srgb")"), std::string::npos) << text;
    EXPECT_EQ(text.rfind(R"({"model":"nominal",)", 0), 0u) << text;
}

TEST(FitJson, ModelOfTextThatIsNotAFitIsNone) {
    EXPECT_FALSE(fit_json_model("not json").has_value());
    EXPECT_FALSE(fit_json_model("[1,2]").has_value());
    EXPECT_FALSE(fit_json_model(R"({"model":3})").has_value());
    EXPECT_EQ(fit_json_model(R"({"model":"gog"})"), "gog");
}

TEST(FitJson, AnIncompleteModelNamesWhatIsMissing) {
    using test::input_error_of;
    EXPECT_NE(input_error_of([] { display_model_from_fit_json("not json", ""); }).find("not a JSON object"),
              std::string::npos);
    const std::string no_gamma = R"({"model":"gog","display":{"peak_cd_m2":100,"black_cd_m2":0.1,"channels":[)"
                                 R"({"encoding":"gog","a":0,"b":0,"k":1,"gamma":2},)"
                                 R"({"encoding":"gog","a":0,"b":0,"k":1},)"
                                 R"({"encoding":"gog","a":0,"b":0,"k":1,"gamma":2}]}})";
    EXPECT_NE(input_error_of([&] {
                  display_model_from_fit_json(no_gamma, "");
              }).find("has no number display.channels[1].gamma"),
              std::string::npos);
    const std::string empty_lut = R"({"peak_cd_m2":1,"black_cd_m2":0,"channels":[)"
                                  R"({"transfer":"lut"},{"transfer":"lut"},{"transfer":"lut"}]})";
    EXPECT_NE(input_error_of([&] { display_model_from_fit_json(empty_lut, ""); }).find("has no points channels[0].lut"),
              std::string::npos);
    const std::string unknown = R"({"peak_cd_m2":1,"black_cd_m2":0,"channels":[)"
                                R"({"encoding":"hlg"},{"encoding":"srgb"},{"encoding":"srgb"}]})";
    EXPECT_NE(input_error_of([&] { display_model_from_fit_json(unknown, ""); }).find("channels[0].encoding"),
              std::string::npos);
}

TEST(FitJson, ACalibrationStoredWithTheOldKeyTransferReadsAsWithEncoding) {
    // Calibrations stored before the key was "encoding" name it "transfer"; the nominal
    // srgb row, the gog row (written out by hand) and a PQ row without its weight read the same.
    const DisplayModel m = DisplayModel::srgb(100.0, 0.1);
    std::string text = nominal_fit_json(m, EncodeSettings{});
    for (std::size_t at = text.find(R"("encoding":)"); at != std::string::npos; at = text.find(R"("encoding":)", at))
        text.replace(at, 11, R"("transfer":)");
    ASSERT_EQ(text.find("encoding"), std::string::npos) << text;
    expect_same_model(m, display_model_from_fit_json(text, m.name));
    // The session's nominal row: an old row is the same display as the one written now (no new row).
    EXPECT_TRUE(same_fit_json(text, nominal_fit_json(m, EncodeSettings{})));
    EXPECT_FALSE(same_fit_json(text, nominal_fit_json(DisplayModel::srgb(100.0, 0.2), EncodeSettings{})));
    EXPECT_FALSE(same_fit_json(text, nominal_fit_json(m, EncodeSettings{10, Dither::spatiotemporal, 0})));
    EXPECT_FALSE(same_fit_json("not json", "not json "));
    const std::string gog = R"({"peak_cd_m2":101,"black_cd_m2":0.3,"channels":[)"
                            R"({"transfer":"gog","a":0.1,"b":0.5,"k":2,"gamma":2},)"
                            R"({"transfer":"gog","a":0.1,"b":0.5,"k":8,"gamma":2},)"
                            R"({"transfer":"gog","a":0.1,"b":0.5,"k":1,"gamma":2}]})";
    const DisplayModel g = display_model_from_fit_json(gog, "old");
    // L(1) = a + (b + k)^gamma: 0.1 + 2.5², 0.1 + 8.5², 0.1 + 1.5².
    EXPECT_DOUBLE_EQ(g.channels[1].max_cd_m2(), 0.1 + 8.5 * 8.5);
    EXPECT_TRUE(g.channels[2].follows("gog"));
    // A PQ channel without pq_weight: its share of the peak.
    const std::string pq = R"({"peak_cd_m2":1000,"black_cd_m2":0,"channels":[)"
                           R"({"transfer":"pq","black_cd_m2":0,"white_cd_m2":200},)"
                           R"({"transfer":"pq","black_cd_m2":0,"white_cd_m2":700},)"
                           R"({"transfer":"pq","black_cd_m2":0,"white_cd_m2":100}]})";
    EXPECT_DOUBLE_EQ(display_model_from_fit_json(pq, "old").channels[1].parameter[0], 0.7);
}

TEST(FitJson, MeasuredFitKeepsTheRampsAndANullContrastForAZeroBlack) {
    CalibrationReport r;
    r.black_cd_m2 = 0.0;
    r.white_cd_m2 = 100.0;
    r.contrast_ratio = std::numeric_limits<double>::infinity();
    RampReport ramp;
    ramp.channel = Channel::grey;
    ramp.fit = GogFit{0.0, 0.0, std::pow(100.0, 1.0 / 2.2), 2.2, 0.001, 9};
    ramp.levels = 9;
    r.ramps.push_back(ramp);
    const std::array<GogParams, 3> gog = {{{0.0, 0.0, 2.0, 2.2}, {0.0, 0.0, 3.0, 2.2}, {0.0, 0.0, 1.0, 2.2}}};
    const DisplayModel m = DisplayModel::gog(gog, "lab");
    const std::string text = measured_fit_json(r, m, DisplayGeometry{}, "imported");
    EXPECT_NE(text.find(R"("contrast_ratio":null)"), std::string::npos) << text;
    EXPECT_NE(text.find(R"("method":"imported")"), std::string::npos) << text;
    EXPECT_NE(text.find(R"("ramps":[{"channel":"grey","a":0.0,"b":0.0,)"), std::string::npos) << text;
    EXPECT_EQ(fit_json_model(text), "gog");
    expect_same_model(m, display_model_from_fit_json(text, "lab"));
}

}  // namespace
}  // namespace atonlab::display
