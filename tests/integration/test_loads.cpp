// Loads as engineers give them (issue 48, item 5, in part): gravity with a material density, and a body force with
// a history of its own, so that the weight is held while a horizontal coefficient grows. The figures come from
// statics: whatever the block's deformation, its support carries its weight and the sideways force, and the joint's
// friction carries the sideways force until it passes mu times the weight.
#include "contact/result_file.hpp"
#include "support.hpp"

#include <cstdio>

#include <gtest/gtest.h>

using namespace contact;
using contact::testing::parse_or_fail;
using nlohmann::json;

namespace {

// A block 1 x 0.5 (m) on a clamped base, Coulomb mu = 0.5 on the joint, gravity [0, -10] and the density 2500
// (25 kN/m^3); `horizontal`: the block's sideways body force as factors of its weight per load step (none: no
// sideways force).
json block_on_base(const std::vector<double>& horizontal = {}) {
  auto block = [](const std::string& name, double y0, double y1) {
    return json{{"name", name},
                {"material", {{"E", 3e10}, {"nu", 0.2}, {"density", 2500}}},
                {"mesh", {{"block", {{"corners", {{0, y0}, {1, y0}, {1, y1}, {0, y1}}}, {"nx", 8}, {"ny", 4}}}}}};
  };
  json base = block("base", 0, 0.5);
  base["boundary"] = json::array({{{"edge", "bottom"}, {"displacement", {{"x", 0}, {"y", 0}}}}});
  json top = block("block", 0.5, 1.0);
  json job = {
      {"name", "block"},
      {"model", {{"gravity", {0, -10}}}},
      {"bodies", {base, top}},
      {"contacts", {{{"slave", "block.bottom"}, {"master", "base.top"}, {"friction", {{"coefficient", 0.5}}}}}}};
  if (!horizontal.empty()) {
    job["bodies"][1]["body_force"] = {{"value", {25000, 0}}, {"history", horizontal}};
    job["loading"] = {{"factors", std::vector<double>(horizontal.size(), 1.0)}};
  }
  return job;
}

}  // namespace

// The weight from gravity and density is the body force rho g: the same answer bit for bit.
TEST(Loads, GravityTimesDensityIsTheBodyForceOfTheWeight) {
  const Result by_gravity = contact::testing::run(block_on_base());
  json explicit_force = block_on_base();
  explicit_force["model"].erase("gravity");
  for (auto& b : explicit_force["bodies"]) {
    b["material"].erase("density");
    b["body_force"] = {0, -25000};
  }
  const Result by_force = contact::testing::run(explicit_force);
  ASSERT_TRUE(by_gravity.converged && by_force.converged) << by_gravity.message << by_force.message;
  for (size_t a = 0; a < 2; ++a)
    EXPECT_EQ(by_gravity.steps.back().bodies[a].displacement, by_force.steps.back().bodies[a].displacement);
  // The base's support carries both weights: 25 kN/m^3 x 0.5 m^2 each.
  EXPECT_NEAR(by_gravity.steps.back().bodies[0].reaction_total.y(), 25000.0, 1e-6);
}

// The weight held at factor 1 in every step while the sideways force grows 0, 0.2, 0.4 of it: the support carries
// the weight and the sideways force of each step, and the joint's friction the sideways force.
TEST(Loads, ABodyForceWithAHistoryGrowsWhileTheWeightIsHeld) {
  const std::vector<double> h = {0.0, 0.2, 0.4};
  const Problem problem = parse_or_fail(block_on_base(h));
  ASSERT_EQ(problem.bodies[1].body_force_history, h);
  const Result r = contact::testing::solve_quietly(problem);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_EQ(r.steps.size(), 3u);
  const double weight = 25000 * 0.5;  // of one body
  for (size_t k = 0; k < 3; ++k) {
    const Step& s = r.steps[k];
    EXPECT_NEAR(s.bodies[0].reaction_total.y(), 2 * weight, 1e-6 * weight) << "step " << k;
    EXPECT_NEAR(s.bodies[0].reaction_total.x(), -h[k] * weight, 1e-6 * weight) << "step " << k;
    EXPECT_NEAR(std::abs(r.step_history[k].tangential_force[0]), h[k] * weight, 1e-6 * weight) << "step " << k;
  }
}

// Past mu times the weight no friction holds the block: statics refuses the step, with the ratio 0.6 / 0.5.
TEST(Loads, ASidewaysForcePastFrictionIsRefusedAtItsStepWithTheRatio) {
  const Result r = contact::testing::run(block_on_base({0.0, 0.3, 0.6}));
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.message.find("load step 3 of 3"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("1.200"), std::string::npos) << r.message;
  EXPECT_EQ(r.steps.size(), 2u);  // the steps that held
}

TEST(Loads, ABodyForceHistoryIsOnePerStepAndADensityIsNotNegative) {
  json job = block_on_base({0.0, 0.2});
  job["loading"] = {{"factors", {1, 1, 1}}};
  auto parsed = job::parse(job);
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(parsed.errors[0].pointer, "/bodies/1/body_force/history");
  EXPECT_NE(parsed.errors[0].message.find("history has 2 load factors but the job has 3"), std::string::npos);
  json negative = block_on_base();
  negative["bodies"][0]["material"]["density"] = -1;
  parsed = job::parse(negative);
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(parsed.errors[0].pointer, "/bodies/0/material/density");
}

// The joint the block rests on, read as an engineer reads it (JointResults), from statics: the sideways force H at
// the block's centroid (0.25 above the joint) moves the normal force's line of action by H 0.25 / W from the middle
// (0.5 along the joint), and friction carries H: |T| / (mu N) = (H / W) / mu. The result file keeps them.
TEST(Loads, TheJointUnderTheBlockHasTheCentreOfPressureAndTheFrictionUtilisationOfStatics) {
  const std::vector<double> h = {0.0, 0.2, 0.4};
  const Result r = contact::testing::run(block_on_base(h));
  ASSERT_TRUE(r.converged) << r.message;
  for (size_t k = 0; k < h.size(); ++k) {
    const JointResults& j = r.steps[k].pairs[0].joint;
    EXPECT_NEAR(j.centre_of_pressure, 0.5 + 0.25 * h[k], 1e-8) << "step " << k;
    EXPECT_NEAR(j.eccentricity, 0.5 * h[k], 2e-8) << "step " << k;
    EXPECT_NEAR(j.friction_utilisation, h[k] / 0.5, 1e-8) << "step " << k;
    EXPECT_GE(j.open_fraction, 0.0);
    EXPECT_LE(j.open_fraction, 1.0);
  }
  const std::string path = ::testing::TempDir() + "/joint_results.hdf";
  io::write_result(path, parse_or_fail(block_on_base(h)), r);
  const io::ResultFile back = io::read_result(path);
  ASSERT_EQ(back.steps.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    const JointResults &a = r.steps[k].pairs[0].joint, &b = back.steps[k].pairs[0].joint;
    EXPECT_EQ(a.centre_of_pressure, b.centre_of_pressure);
    EXPECT_EQ(a.eccentricity, b.eccentricity);
    EXPECT_EQ(a.friction_utilisation, b.friction_utilisation);
    EXPECT_EQ(a.open_fraction, b.open_fraction);
    // The derivation from the nodes (as for a file written before the columns) gives the same.
    const JointResults d = joint_results(back.steps[k].pairs[0]);
    EXPECT_NEAR(d.centre_of_pressure, a.centre_of_pressure, 1e-12);
    EXPECT_NEAR(d.friction_utilisation, a.friction_utilisation, 1e-12);
  }
  std::remove(path.c_str());
}

namespace {

// The block on its base, its top edge loaded by a normal pressure p and a shear s (kN/m); as one traction, or as two
// conditions on the same edge (each with its own history when given).
json block_loaded_on_top(bool two_conditions, std::vector<double> p_history = {}, std::vector<double> s_history = {}) {
  json job = block_on_base();
  const double p = 20000, s = 4000;
  json& boundary = job["bodies"][1]["boundary"];
  if (!two_conditions) {
    boundary = json::array({{{"edge", "top"}, {"traction", {s, -p}}}});
    return job;
  }
  json precompression = {{"edge", "top"}, {"traction", {{"normal", p}}}};
  json shear = {{"edge", "top"}, {"traction", {s, 0}}};
  if (!p_history.empty()) {
    precompression["history"] = p_history;
    shear["history"] = s_history;
    job["loading"] = {{"factors", std::vector<double>(p_history.size(), 1.0)}};
  }
  boundary = json::array({precompression, shear});
  return job;
}

}  // namespace

// Loads on one edge add: a normal pressure and a shear as two conditions give the answer of the one traction that is
// their sum (to rounding), and with histories of their own the precompression is held while the shear grows: the
// support carries both weights plus p at every step and the shear of that step.
TEST(Loads, TwoLoadsOnOneEdgeAddAndKeepTheirOwnHistories) {
  const Result one = contact::testing::run(block_loaded_on_top(false));
  const Result two = contact::testing::run(block_loaded_on_top(true));
  ASSERT_TRUE(one.converged && two.converged) << one.message << two.message;
  for (size_t a = 0; a < 2; ++a) {
    const auto& u1 = one.steps.back().bodies[a].displacement;
    EXPECT_LE((u1 - two.steps.back().bodies[a].displacement).cwiseAbs().maxCoeff(), 1e-10 * u1.cwiseAbs().maxCoeff());
  }
  const std::vector<double> held = {1, 1, 1}, ramp = {0, 0.5, 1};
  const Result r = contact::testing::run(block_loaded_on_top(true, held, ramp));
  ASSERT_TRUE(r.converged) << r.message;
  for (size_t k = 0; k < 3; ++k) {
    const Eigen::Vector2d support = r.steps[k].bodies[0].reaction_total;
    EXPECT_NEAR(support.y(), 25000.0 + 20000.0, 1e-6 * 45000.0) << "step " << k;
    EXPECT_NEAR(support.x(), -4000.0 * ramp[k], 1e-6 * 45000.0) << "step " << k;
  }
  // A displacement is alone on its edge; a load there belongs in the same condition.
  json fixed = block_loaded_on_top(true);
  fixed["bodies"][1]["boundary"][0] = {{"edge", "top"}, {"displacement", {{"y", 0}}}};
  const auto parsed = job::parse(fixed);
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(parsed.errors[0].pointer, "/bodies/1/boundary/1/edge");
  EXPECT_NE(parsed.errors[0].message.find("is the only condition of its edge"), std::string::npos)
      << parsed.errors[0].message;
}

// The FEM-BEM indicator reads a side's loads summed: the two-condition job's indicator is the one traction's.
TEST(Loads, TheBoundaryElementIndicatorSumsTheLoadsOfASide) {
  auto adaptive = [](json job) {
    job["adaptivity"] = {{"indicator", "fem_bem"}, {"max_steps", 1}, {"bodies", {"block"}}};
    return job;
  };
  const Result one = contact::testing::run(adaptive(block_loaded_on_top(false)));
  const Result two = contact::testing::run(adaptive(block_loaded_on_top(true)));
  ASSERT_FALSE(one.steps.empty());
  ASSERT_FALSE(two.steps.empty());
  const Eigen::VectorXd& a = one.steps.back().bodies[1].indicator_cell;
  const Eigen::VectorXd& b = two.steps.back().bodies[1].indicator_cell;
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 0);
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), 1e-8 * a.cwiseAbs().maxCoeff());
}
