// Helpers shared by the tests that run whole jobs: the job examples and a quiet solve.
#pragma once

#include "job/job.hpp"
#include "solve.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace contact::testing {

// api/examples/<name> as JSON.
inline nlohmann::json example(const std::string& name) {
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/examples/" + name);
  EXPECT_TRUE(in.good()) << name;
  return nlohmann::json::parse(in);
}

// Parses (the test fails on validation errors) and solves without observer or cancellation.
inline Result run(const nlohmann::json& job) {
  auto parsed = job::parse(job);
  EXPECT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  if (!parsed.ok()) return {};
  Observer quiet;
  CancelToken cancel;
  return solve(*parsed.problem, quiet, cancel);
}

}  // namespace contact::testing
