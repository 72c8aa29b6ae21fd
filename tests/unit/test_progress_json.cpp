// Progress as JSON at scale (contact/progress_json.hpp): the totals are the sums over every pair and body, an event
// lists a bounded number of pairs whatever the job's size (the ones selected, and the two its totals name), and the
// job's output.progress_pairs is checked against the job's pair names.
#include <gtest/gtest.h>

#include "contact/job.hpp"
#include "contact/progress_json.hpp"

#include <cmath>
#include <set>
#include <string>

using contact::IterationReport;
using contact::PairReport;
using contact::io::bounded_progress;
using contact::io::iteration_json;
using contact::io::ProgressSelection;
using nlohmann::json;

namespace {

// n pairs "p<k>" of `nodes` slave nodes each; pair k has force k + 1, peak pressure 1 + (k * 37 % n) (a permutation:
// one pair holds the maximum), k % 3 changed nodes; every third pair has friction: stick at even nodes.
IterationReport report(int n, int nodes = 50, int bodies = 10) {
  IterationReport r;
  r.iteration = 3;
  for (int b = 0; b < bodies; ++b) r.bodies.push_back({"body" + std::to_string(b), 10 + b, 20 + 2 * b, b % 2});
  for (int k = 0; k < n; ++k) {
    PairReport p;
    p.name = "p" + std::to_string(k);
    p.force = k + 1;
    p.max_pressure = 1 + (k * 37 % n);
    p.active_nodes = nodes / 2;
    p.changed_nodes = (k % 3) * (k % 2 ? -1 : 1);
    for (int j = 0; j < nodes; ++j) {
      p.positions.push_back(j);
      p.pressures.push_back(j < nodes / 2 ? 1.0 : 0.0);
    }
    if (k % 3 == 0) {
      p.friction = "coulomb";
      p.friction_coefficient = 0.5;
      p.tangential_force = -0.5 * k;
      for (int j = 0; j < nodes; ++j) {
        p.tangential_tractions.push_back(0.1);
        p.stick.push_back(j % 2 == 0);
      }
    }
    r.pairs.push_back(p);
  }
  return r;
}

std::set<std::string> listed(const json& progress) {
  std::set<std::string> names;
  for (const auto& p : progress["pairs"]) names.insert(p["name"].get<std::string>());
  return names;
}

}  // namespace

TEST(ProgressJson, TheTotalsAreTheSumsOverEveryPairAndBody) {
  const IterationReport r = report(100);
  const json full = iteration_json(r);
  const json bounded = bounded_progress(full, {});
  const json& s = bounded["pairs_summary"];
  double force = 0, tangential = 0, active = 0, changed = 0, stick = 0, slip = 0;
  int pairs_changed = 0, friction = 0;
  for (const auto& p : r.pairs) {
    force += p.force;
    active += p.active_nodes;
    changed += std::abs(p.changed_nodes);
    pairs_changed += p.changed_nodes != 0;
    if (!p.stick.empty()) {
      ++friction;
      tangential += p.tangential_force;
      for (size_t j = 0; j < p.stick.size(); ++j)
        if (p.pressures[j] > 0) (p.stick[j] ? stick : slip) += 1;
    }
  }
  EXPECT_EQ(s["count"], 100);
  EXPECT_DOUBLE_EQ(s["force"].get<double>(), force);
  EXPECT_DOUBLE_EQ(s["tangential_force"].get<double>(), tangential);
  EXPECT_EQ(s["active_nodes"].get<double>(), active);
  EXPECT_EQ(s["changed_nodes"].get<double>(), changed);
  EXPECT_EQ(s["pairs_changed"], pairs_changed);
  EXPECT_EQ(s["friction_pairs"], friction);
  EXPECT_EQ(s["stick_nodes"].get<double>(), stick);  // 25 nodes in contact a pair, 13 of them at even indices
  EXPECT_EQ(s["slip_nodes"].get<double>(), slip);
  EXPECT_EQ(stick, 34 * 13);
  EXPECT_EQ(s["max_pressure"].get<double>(), 100.0);
  // 1 + (k * 37 % 100) = 100 at k * 37 = 99 (mod 100): k = 27.
  EXPECT_EQ(s["max_pressure_pair"], "p27");
  EXPECT_EQ(s["most_changed_pair"], "p2");  // the first pair with |changed| = 2
  const json& b = bounded["bodies_summary"];
  EXPECT_EQ(b["count"], 10);
  EXPECT_EQ(b["elements"].get<double>(), 10 * 10 + 45);
  EXPECT_EQ(b["dofs"].get<double>(), 10 * 20 + 90);
  EXPECT_EQ(b["elements_refined"].get<double>(), 5);
}

TEST(ProgressJson, PastSixteenPairsAnEventListsTheSelectedPairsAndTheTwoItsTotalsName) {
  const json full = iteration_json(report(100));
  json bounded = bounded_progress(full, {});
  EXPECT_EQ(bounded["pairs_listed"], "selected");
  EXPECT_EQ(listed(bounded), (std::set<std::string>{"p27", "p2"}));
  // The listed pairs are as in the full object, profiles included, in the job's order.
  EXPECT_EQ(bounded["pairs"][0], full["pairs"][2]);
  EXPECT_EQ(bounded["pairs"][1], full["pairs"][27]);

  bounded = bounded_progress(full, {{"p1?", "p5"}, false});
  std::set<std::string> want{"p27", "p2", "p5"};
  for (int k = 10; k < 20; ++k) want.insert("p" + std::to_string(k));
  EXPECT_EQ(listed(bounded), want);

  bounded = bounded_progress(full, {{"*"}, false});  // a pattern that matches everything: the first 64
  EXPECT_EQ(bounded["pairs"].size(), contact::io::kMaxPairsSelected);

  bounded = bounded_progress(full, {{}, true});
  EXPECT_EQ(bounded["pairs_listed"], "all");
  EXPECT_EQ(bounded["pairs"], full["pairs"]);
}

TEST(ProgressJson, AFewPairsAreListedAllUnlessTheJobSelects) {
  const json full = iteration_json(report(contact::io::kPairsListedAll));
  EXPECT_EQ(bounded_progress(full, {})["pairs"], full["pairs"]);
  EXPECT_EQ(bounded_progress(full, {})["pairs_listed"], "all");
  const json chosen = bounded_progress(full, {{"p3"}, false});
  EXPECT_EQ(chosen["pairs_listed"], "selected");
  EXPECT_TRUE(listed(chosen).count("p3"));
  EXPECT_LE(listed(chosen).size(), 3u);
}

TEST(ProgressJson, AnEventsSizeDoesNotGrowWithTheNumberOfPairsOrBodies) {
  const std::string small = bounded_progress(iteration_json(report(20, 200, 10)), {}).dump();
  const std::string large = bounded_progress(iteration_json(report(4000, 200, 2000)), {}).dump();
  const std::string full = iteration_json(report(4000, 200, 2000)).dump();
  EXPECT_GT(full.size(), 10'000'000u);
  EXPECT_LT(large.size(), 16'000u);
  EXPECT_LT(large.size(), small.size() + 1000);  // two listed pairs either way; the body list dropped
  const json bounded = json::parse(large);
  EXPECT_FALSE(bounded.contains("bodies"));
  EXPECT_EQ(bounded["bodies_listed"], "none");
  EXPECT_EQ(bounded["bodies_summary"]["count"], 2000);
}

TEST(ProgressJson, TheJobsProgressPairsAreCheckedAgainstItsPairNames) {
  json job = json::parse(R"({
    "bodies": [
      {"name": "upper", "material": {"E": 1, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, 0], [1, 0], [1, 1], [0, 1]], "nx": 1, "ny": 1}},
       "boundary": [{"edge": "top", "displacement": {"x": 0, "y": -0.001}}]},
      {"name": "lower", "material": {"E": 1, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, -1], [1, -1], [1, 0], [0, 0]], "nx": 1, "ny": 1}},
       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]}],
    "contacts": [{"slave": "upper.bottom", "master": "lower.top"}],
    "output": {"progress_pairs": ["upper*"]}})");
  auto r = contact::job::parse(job);
  ASSERT_TRUE(r.ok()) << contact::job::format_errors(r.errors);
  EXPECT_EQ(r.problem->output.progress_pairs, std::vector<std::string>{"upper*"});

  job["output"]["progress_pairs"] = {"upper*", "wall_*"};
  r = contact::job::parse(job);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].pointer, "/output/progress_pairs/1");
  EXPECT_NE(r.errors[0].message.find("'wall_*' matches no contact pair; the pairs are upper.bottom-lower.top"),
            std::string::npos)
      << r.errors[0].message;

  job["output"]["progress_pairs"] = "upper*";
  r = contact::job::parse(job);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].pointer, "/output/progress_pairs");
  EXPECT_NE(r.errors[0].message.find("must be an array"), std::string::npos);

  job["output"]["progress_pairs"] = json::array();
  for (int k = 0; k < 17; ++k) job["output"]["progress_pairs"].push_back("upper*");
  r = contact::job::parse(job);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].message.find("at most 16"), std::string::npos);

  job["output"]["progress_pairs"] = {""};
  r = contact::job::parse(job);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].pointer, "/output/progress_pairs/0");
}

TEST(ProgressJson, AnAdaptiveStepCarriesItsEstimatesAndAnEstimateThatCouldNotBeMadeIsNull) {
  contact::AdaptiveStepReport r;
  r.step = 3;
  r.bodies.resize(2);
  r.bodies[0].name = "upper";
  r.bodies[0].elements = 40;
  r.bodies[0].dofs = 90;
  r.bodies[0].elements_refined = 7;
  r.estimate = 0.03;
  r.pressure_estimate = 0.0012;
  r.force = 150.5;
  r.peak_pressure = 193.7;
  const nlohmann::json j = contact::io::adaptive_step_json(r);
  EXPECT_EQ(j["step"], 3);
  EXPECT_EQ(j["bodies"][0]["name"], "upper");
  EXPECT_EQ(j["bodies"][0]["cells"], 40);
  EXPECT_EQ(j["bodies"][0]["unknowns"], 90);
  EXPECT_EQ(j["bodies"][0]["refined"], 7);
  EXPECT_EQ(j["pressure_estimate"], 0.0012);
  EXPECT_EQ(j["estimate"], 0.03);
  EXPECT_FALSE(j.contains("type"));  // the writer names it (contact-solve's line, contactd's event)
  // The changes the stop test reads, and the step they are read against.
  r.compared_with = 1;
  r.force_change = 0.001;
  r.extent_change = 0.002;
  r.stick_change = 0.003;
  r.tangential_change = 0.004;
  const nlohmann::json changes = contact::io::adaptive_step_json(r);
  EXPECT_EQ(changes["compared_with"], 1);
  EXPECT_EQ(changes["force_change"], 0.001);
  EXPECT_EQ(changes["extent_change"], 0.002);
  EXPECT_EQ(changes["stick_change"], 0.003);
  EXPECT_EQ(changes["tangential_change"], 0.004);
  r.pressure_estimate = std::nan("");  // the zz indicator: no estimate
  r.compared_with = -1;                // no step with half the unknowns yet: no changes
  r.force_change = r.peak_change = r.extent_change = r.stick_change = r.tangential_change = std::nan("");
  const nlohmann::json line = nlohmann::json::parse(contact::io::adaptive_step_json(r).dump());
  EXPECT_TRUE(line["pressure_estimate"].is_null());
  EXPECT_EQ(line["compared_with"], -1);
  EXPECT_TRUE(line["force_change"].is_null());
  EXPECT_TRUE(line["stick_change"].is_null());
}
