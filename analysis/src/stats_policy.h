#pragma once
// The Boost.Math policy used by analysis/: errors become errno + a quiet
// value instead of exceptions (callers check finiteness themselves; the data
// must never make analysis/ throw), and doubles are not promoted to long
// double (bootstrap refits evaluate these millions of times).
#include <boost/math/policies/policy.hpp>

namespace atonlab::analysis::detail {

using StatsPolicy =
    boost::math::policies::policy<boost::math::policies::domain_error<boost::math::policies::errno_on_error>,
                                  boost::math::policies::pole_error<boost::math::policies::errno_on_error>,
                                  boost::math::policies::overflow_error<boost::math::policies::errno_on_error>,
                                  boost::math::policies::evaluation_error<boost::math::policies::errno_on_error>,
                                  boost::math::policies::rounding_error<boost::math::policies::errno_on_error>,
                                  boost::math::policies::promote_double<false>>;

}  // namespace atonlab::analysis::detail
