// One source of the job's defaults and one wording of its rules (issue 27, item 3). The rule on method and
// enforcement that both the reader and solve() check is one function (contact::settings_conflict).
#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "contact/job.hpp"
#include "contact/solve.hpp"

using contact::job::parse;
using contact::job::ParseResult;
using nlohmann::json;

namespace {

std::string listing(const ParseResult& r) { return contact::job::format_errors(r.errors); }

// Two blocks pressed together, each held against rigid motion: a job every method can run.
json pressed_blocks_job() {
  return json::parse(R"({
    "bodies": [
      {"name": "upper", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, 0], [2, 0], [2, 1], [0, 1]], "nx": 2, "ny": 1}},
       "boundary": [{"edge": "left", "displacement": {"x": 0}}, {"edge": "top", "displacement": {"y": -0.001}}]},
      {"name": "lower", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, -1], [2, -1], [2, 0], [0, 0]], "nx": 2, "ny": 1}},
       "boundary": [{"edge": "left", "displacement": {"x": 0}}, {"edge": "bottom", "displacement": {"y": 0}}]}
    ],
    "contacts": [{"slave": "upper.bottom", "master": "lower.top"}]
  })");
}

}  // namespace

// Exact enforcement with a method that iterates on the penalty problem: one rule (contact::settings_conflict),
// reported by the reader at the enforcement's pointer and by solve() for a Problem built in code, in the same words.
TEST(SettingsConflict, ExactEnforcementOfAPenaltyIterationIsRefusedInOneWordingByTheReaderAndBySolve) {
  for (const char* method : {"neumann", "robin"}) {
    contact::SolverSettings settings;
    settings.method = *contact::method_named(method);
    settings.enforcement = contact::Enforcement::exact;
    const std::string rule = contact::settings_conflict(settings);
    ASSERT_NE(rule.find("iterates on the penalty problem"), std::string::npos) << rule;

    json job = pressed_blocks_job();
    job["solver"] = {{"method", method}, {"enforcement", "exact"}};
    const ParseResult refused = parse(job);
    ASSERT_EQ(refused.errors.size(), 1u) << listing(refused);
    EXPECT_EQ(refused.errors[0].pointer, "/solver/enforcement");
    EXPECT_EQ(refused.errors[0].message, rule);

    job["solver"] = {{"method", method}};  // penalty by default: valid; then made exact in code
    ParseResult read = parse(job);
    ASSERT_TRUE(read.ok()) << listing(read);
    contact::Problem problem = std::move(*read.problem);
    problem.solver.enforcement = contact::Enforcement::exact;
    contact::Observer observer;
    contact::CancelToken cancel;
    const contact::Result result = contact::solve(problem, observer, cancel);
    EXPECT_EQ(result.stop_reason, contact::StopReason::error);
    EXPECT_NE(result.message.find(rule), std::string::npos) << result.message;
  }
  // Every other combination can run.
  for (const auto method : {contact::Method::neumann, contact::Method::robin, contact::Method::monolithic,
                            contact::Method::interface_newton})
    for (const auto enforcement : {contact::Enforcement::exact, contact::Enforcement::penalty,
                                   contact::Enforcement::augmented_lagrangian}) {
      contact::SolverSettings settings;
      settings.method = method;
      settings.enforcement = enforcement;
      const bool conflict = contact::iterates_on_penalty(method) && enforcement == contact::Enforcement::exact;
      EXPECT_EQ(contact::settings_conflict(settings).empty(), !conflict)
          << contact::to_string(method) << " " << contact::to_string(enforcement);
    }
}
