// How atonlab reads ArgyllCMS spotread's terminal output
// (runner/src/calibrate/spotread_output.h): the texts are spotread 3.2.0's own
// printf formats (spectro/spotread.c, spectro/instappsup.c).
#include <gtest/gtest.h>

#include "calibrate/spotread_output.h"

namespace atonlab::runner::spotread {
namespace {

TEST(SpotreadOutput, ResultLinesInEveryColourSpaceGiveXyzExactly) {
    // printf("\n Result is XYZ: %f %f %f, Yxy: %f %f %f\n") with -x; the default is D50 Lab.
    auto xyz = parse_result(" Result is XYZ: 95.045600 100.000000 108.905800, Yxy: 100.000000 0.312700 0.329000");
    ASSERT_TRUE(xyz.has_value());
    EXPECT_EQ(xyz->x, 95.0456);
    EXPECT_EQ(xyz->y, 100.0);
    EXPECT_EQ(xyz->z, 108.9058);
    xyz = parse_result(" Result is XYZ: 0.237625 0.250000 0.272250, D50 Lab: 2.258190 0.107013 -0.063021");
    ASSERT_TRUE(xyz.has_value());
    EXPECT_EQ(xyz->y, 0.25);
    // Negative values (noise at black) are parsed; refusing them is the session's job.
    xyz = parse_result(" Result is XYZ: -0.000100 0.000000 0.001000, LCh: 0 0 0");
    ASSERT_TRUE(xyz.has_value());
    EXPECT_EQ(xyz->x, -0.0001);
    EXPECT_FALSE(parse_result(" Result is XYZ: 1.0 2.0, Yxy: 1 2 3").has_value());
    EXPECT_FALSE(parse_result(" Result is XYZ: 1.0 2.0 nan, Yxy: 1 2 3").has_value());
    EXPECT_FALSE(parse_result(" Result is Y: 12.000000, L*: 41.2").has_value());  // ambient mono: no XYZ
}

TEST(SpotreadOutput, EventsAreFoundInOrder) {
    const std::string prompt =
        "\nPlace instrument on spot to be measured,\n'h' to toggle high res., 'k' to do a calibration\n"
        "Hit ESC or Q to exit, any other key to take a reading: ";
    Scan s = scan(prompt);
    EXPECT_EQ(s.state, State::ready);
    EXPECT_EQ(s.end, prompt.size());
    // A result line counts once its newline has arrived.
    EXPECT_EQ(scan("\n Result is XYZ: 1.000000 2.000000 3.0").state, State::busy);
    s = scan("\n Result is XYZ: 1.000000 2.000000 3.000000, Yxy: 2 0.1 0.2\n" + prompt);
    EXPECT_EQ(s.state, State::result);
    EXPECT_EQ(s.line, "Result is XYZ: 1.000000 2.000000 3.000000, Yxy: 2 0.1 0.2");
    // Errors: an instrument error waiting for a key, a fatal error line.
    s = scan("\n\nSpot read failed due to communication problem.\nHit Esc or Q to give up, any other key to retry:");
    EXPECT_EQ(s.state, State::failed);
    EXPECT_EQ(s.line, "Spot read failed due to communication problem.");
    s = scan("spotread: Error - No instrument at port 1\n");
    EXPECT_EQ(s.state, State::failed);
    EXPECT_EQ(s.line, "spotread: Error - No instrument at port 1");
    EXPECT_EQ(scan("Got 'Instrument not responding' (Communications error) error.\nHit Esc").state, State::failed);
}

TEST(SpotreadOutput, ACalibrationRequestGivesItsInstruction) {
    const std::string out =
        "\nSpot read needs a calibration before continuing\n"
        "Place cap on the instrument, or place on a dark surface,\n"
        "or place on the calibration reference,\n"
        " and then hit any key to continue,\n"
        " or hit Esc or Q to abort: ";
    const Scan s = scan(out);
    EXPECT_EQ(s.state, State::calibration);
    EXPECT_EQ(calibration_instruction(out),
              "Place cap on the instrument, or place on a dark surface, or place on the calibration reference");
}

}  // namespace
}  // namespace atonlab::runner::spotread
