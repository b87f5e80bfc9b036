// The JSON columns' parser and writer (atonlab/store/json.h, nlohmann::json):
// values read by JSON pointer, absent or mistyped values as "none", invalid
// text refused with a StoreError that names it, every finite double written
// and read back bit for bit, non-finite numbers as null, bytes that are not
// UTF-8 written without throwing.
#include <gtest/gtest.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "atonlab/store/error.h"
#include "atonlab/store/json.h"

namespace atonlab::store {
namespace {

TEST(StoreJson, ReadsNumbersStringsBooleansAndArrays) {
    const nlohmann::json j = parse_json(R"({"model":"gog","peak":120.5,"n":7,"ok":true,"no":false,
                           "channels":[{"gamma":2.2},{"gamma":2.4e0},{"gamma":-0.125}],"s":"12","inf":null})");
    EXPECT_EQ(string_at(j, "/model"), "gog");
    EXPECT_EQ(number_at(j, "/peak"), 120.5);
    EXPECT_EQ(number_at(j, "/n"), 7.0);
    EXPECT_EQ(number_at(j, "/channels/1/gamma"), 2.4);
    EXPECT_EQ(number_at(j, "/channels/2/gamma"), -0.125);
    EXPECT_EQ(array_at(j, "/channels").size(), 3u);
    EXPECT_EQ(array_at(j, "/model").size(), 0u);
    EXPECT_EQ(array_at(j, "/missing").size(), 0u);
    EXPECT_EQ(boolean_at(j, "/ok"), true);
    EXPECT_EQ(boolean_at(j, "/no"), false);
    EXPECT_FALSE(number_at(j, "/s").has_value());    // a string, not a number
    EXPECT_FALSE(number_at(j, "/inf").has_value());  // null: how a non-finite number is written
    EXPECT_FALSE(number_at(j, "/missing").has_value());
    EXPECT_FALSE(number_at(j, "/channels/3/gamma").has_value());  // past the end
    EXPECT_FALSE(number_at(j, "/channels/x/gamma").has_value());  // not an index
    EXPECT_FALSE(number_at(j, "/peak/deeper").has_value());       // below a number
    EXPECT_FALSE(string_at(j, "/peak").has_value());
    EXPECT_FALSE(boolean_at(j, "/n").has_value());
    EXPECT_EQ(json_at(j, "/nothing"), nullptr);
    ASSERT_NE(json_at(j, ""), nullptr);
    EXPECT_TRUE(json_at(j, "")->is_object());
    // Shortest round-trip decimal text (what fmt and the old writers wrote) reads back as the same double.
    const double third = 1.0 / 3.0, tiny = 4.9406564584124654e-320, big = 1.7976931348623157e308;
    const nlohmann::json k = parse_json("[0.3333333333333333,4.9406564584124654e-320,1.7976931348623157e+308]");
    EXPECT_EQ(number_at(k, "/0"), third);
    EXPECT_EQ(number_at(k, "/1"), tiny);
    EXPECT_EQ(number_at(k, "/2"), big);
}

TEST(StoreJson, InvalidFitJsonIsAStoreErrorThatNamesIt) {
    for (const char* text : {"{\"a\":", "", "{\"a\":1} trailing", "{\"a\":NaN}", "{'a':1}"}) {
        SCOPED_TRACE(text);
        try {
            parse_json(text, "fit_json of calibration 3");
            ADD_FAILURE() << "accepted";
        } catch (const StoreError& e) {
            EXPECT_EQ(e.kind(), StoreErrc::invalid_argument);
            EXPECT_EQ(std::string(e.what()).rfind("fit_json of calibration 3 is not valid JSON (at byte ", 0), 0u)
                << e.what();
        }
    }
    // Without a name, the message still says what is wrong.
    try {
        parse_json("[1,");
        ADD_FAILURE() << "accepted";
    } catch (const StoreError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("the JSON text is not valid JSON", 0), 0u) << e.what();
    }
}

/// `v` written by dump_json and parsed back, as its bits.
std::uint64_t round_trip_bits(double v) {
    const std::string text = dump_json(nlohmann::ordered_json::array({v}));
    const nlohmann::json back = parse_json(text);
    const nlohmann::json* x = json_at(back, "/0");
    EXPECT_TRUE(x && x->is_number_float()) << text;
    return x && x->is_number() ? std::bit_cast<std::uint64_t>(x->get<double>()) : 0;
}

TEST(StoreJson, EveryFiniteDoubleReadsBackBitForBit) {
    const std::vector<double> hard{0.0,
                                   -0.0,
                                   0.1,
                                   1.0 / 3.0,
                                   2.0 / 3.0,
                                   1e23,  // the classic shortest-digits case (1e23 is not exactly representable)
                                   9007199254740993.0,
                                   std::numeric_limits<double>::denorm_min(),
                                   DBL_MIN,
                                   std::nextafter(DBL_MIN, 0.0),
                                   DBL_MAX,
                                   -DBL_MAX,
                                   DBL_EPSILON,
                                   1.0 + DBL_EPSILON,
                                   5e-324,
                                   123456789012345678.0,
                                   0.30000000000000004};
    for (const double v : hard) EXPECT_EQ(round_trip_bits(v), std::bit_cast<std::uint64_t>(v)) << v;
    // Random bit patterns cover every exponent and mantissa shape.
    std::mt19937_64 rng(20261202);
    int tested = 0;
    while (tested < 20000) {
        const double v = std::bit_cast<double>(rng());
        if (!std::isfinite(v)) continue;
        ASSERT_EQ(round_trip_bits(v), std::bit_cast<std::uint64_t>(v)) << v;
        ++tested;
    }
}

TEST(StoreJson, NonFiniteNumbersAreWrittenAsNull) {
    const nlohmann::ordered_json j{{"nan", std::numeric_limits<double>::quiet_NaN()},
                                   {"inf", std::numeric_limits<double>::infinity()},
                                   {"minus_inf", -std::numeric_limits<double>::infinity()},
                                   {"one", 1.5}};
    EXPECT_EQ(dump_json(j), R"({"nan":null,"inf":null,"minus_inf":null,"one":1.5})");
    const nlohmann::json back = parse_json(dump_json(j));
    EXPECT_FALSE(number_at(back, "/nan").has_value());
    EXPECT_FALSE(number_at(back, "/inf").has_value());
    EXPECT_EQ(number_at(back, "/one"), 1.5);
}

TEST(StoreJson, BytesThatAreNotUtf8AreWrittenAsReplacementCharacters) {
    // An instrument's transcript may hold any byte; writing it must not throw.
    const nlohmann::ordered_json j{{"transcript", std::string("ok \xff\xfe end")}, {"name", "café"}};
    std::string text;
    ASSERT_NO_THROW(text = dump_json(j));
    const nlohmann::json back = parse_json(text);
    EXPECT_EQ(string_at(back, "/transcript"), "ok \xEF\xBF\xBD\xEF\xBF\xBD end");  // U+FFFD twice
    EXPECT_EQ(string_at(back, "/name"), "café");
}

TEST(StoreJson, KeysKeepTheOrderTheyWereWrittenIn) {
    const nlohmann::ordered_json j{{"z", 1}, {"a", 2}, {"m", "x\"y"}};
    EXPECT_EQ(dump_json(j), R"({"z":1,"a":2,"m":"x\"y"})");
    EXPECT_EQ(dump_json(j, 2), "{\n  \"z\": 1,\n  \"a\": 2,\n  \"m\": \"x\\\"y\"\n}");
}

}  // namespace
}  // namespace atonlab::store
