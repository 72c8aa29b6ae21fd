// Dimension checks at the boundaries between modules, active in debug builds (CMAKE_BUILD_TYPE=Debug, where
// NDEBUG is not defined) and compiled out in release builds: a mismatch is a programming error, caught where it
// happens with what was expected, instead of as Eigen's generic assertion deep inside an expression, or not at all.
#pragma once

#include <cstdio>
#include <cstdlib>

#ifdef NDEBUG
#define CONTACT_ASSERT_SIZE(actual, expected, what) ((void)0)
#else
#define CONTACT_ASSERT_SIZE(actual, expected, what)                                                               \
  do {                                                                                                            \
    const long long contact_actual_ = static_cast<long long>(actual);                                             \
    const long long contact_expected_ = static_cast<long long>(expected);                                         \
    if (contact_actual_ != contact_expected_) {                                                                   \
      std::fprintf(stderr, "%s:%d: %s has size %lld, expected %lld\n", __FILE__, __LINE__, what, contact_actual_, \
                   contact_expected_);                                                                            \
      std::abort();                                                                                               \
    }                                                                                                             \
  } while (false)
#endif
