#pragma once
// Expects make() to throw a ProcedureError that names `parameter`.
#include <gtest/gtest.h>

#include <string>

#include "atonlab/protocols/procedure.h"

namespace atonlab::test {

template <class F>
void expect_bad(F make, const std::string& parameter) {
    try {
        make();
        ADD_FAILURE() << "no ProcedureError for " << parameter;
    } catch (const protocols::ProcedureError& e) {
        EXPECT_EQ(e.parameter(), parameter) << e.what();
    }
}

}  // namespace atonlab::test
