#pragma once
// Every skip says why in a form scripts/skipped_tests.py reads from CTest's
// output (docs/testing.md, "Skips"): its message starts with one of
//
//   "no GPU: "          what a machine may lack and CI may too: an OpenGL 4.5
//                       context, a display server, a window system's depth;
//   "missing tool: "    a program, font or library feature that
//                       scripts/setup.sh installs: under CI=true,
//                       scripts/test.sh fails on it, since it hides a check;
//   "not applicable: "  the test cannot apply here (running as root, a long
//                       form left for ATONLAB_LONG_TESTS=1, a race lost).
//
// Each macro returns from the test like GTEST_SKIP(), and takes the rest of
// the message with <<:  ATONLAB_SKIP_MISSING_TOOL() << "gnuplot is not installed";
// Shell tests say the same on a line of their own before they exit 77.
#include <gtest/gtest.h>

#define ATONLAB_SKIP_NO_GPU() GTEST_SKIP() << "no GPU: "
#define ATONLAB_SKIP_MISSING_TOOL() GTEST_SKIP() << "missing tool: "
#define ATONLAB_SKIP_NOT_APPLICABLE() GTEST_SKIP() << "not applicable: "
