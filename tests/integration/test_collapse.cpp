// The collapse analysis (issue 48, items 1-3): the live loads raised to their collapse multiplier lambda_c, the
// bracket, its cost in solves, and the verdict with its mechanism. Every figure comes from the statics of rigid
// blocks (exact for the elastic bodies too: small displacements, no-tension joints, Coulomb friction):
//  - a column of n blocks b x h under a horizontal body force lambda times its weight overturns about the base's toe
//    when lambda (n h / 2) = b / 2, lambda_c = b / (n h), below every upper joint's b / (k h) and below mu;
//  - the top block of a column pushed at its top slides when lambda P = mu w (its weight w), below the rocking of
//    any joint (w b / (2 h) for the top one);
//  - a block on a slope of angle alpha (tan alpha < mu), pushed sideways by lambda times its weight, slides when
//    lambda = (mu - tan alpha) / (1 + mu tan alpha);
//  - a single block b x h overturns under lambda times its weight sideways at lambda_c = b / h, about the toe on
//    the side the load pushes towards.
#include "contact/result_file.hpp"
#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>

using namespace contact;
using contact::testing::parse_or_fail;
using nlohmann::json;

namespace {

json block(const std::string& name, const std::vector<std::array<double, 2>>& corners, int nx, int ny,
           double density = 1.0) {
  json c = json::array();
  for (const auto& p : corners) c.push_back({p[0], p[1]});
  return {{"name", name},
          {"material", {{"E", 1e5}, {"nu", 0.2}, {"density", density}}},
          {"mesh", {{"block", {{"corners", c}, {"nx", nx}, {"ny", ny}}}}},
          {"boundary", json::array()}};
}

json ground(double x0, double x1) {
  json g = block("ground", {{x0, -1}, {x1, -1}, {x1, 0}, {x0, 0}}, 12, 3, 0.0);
  g["boundary"] = json::array({{{"edge", "bottom"}, {"displacement", {{"x", 0}, {"y", 0}}}}});
  return g;
}

// A column of n blocks b x h on a clamped ground, Coulomb mu on every joint, gravity [0, -10], density 1.
// live: "body" (a horizontal body force of `push` per volume on every block), or "top" (a force [push, 0] on the top
// block's top edge).
json column(int n, double b, double h, double mu, const std::string& live, double push = 10.0) {
  json bodies = json::array({ground(-1, b + 1)});
  json contacts = json::array();
  for (int i = 0; i < n; ++i) {
    const std::string name = "b" + std::to_string(i + 1);
    json blk = block(name, {{0, i * h}, {b, i * h}, {b, (i + 1) * h}, {0, (i + 1) * h}}, 4, 4);
    if (live == "body") blk["body_force"] = {{"value", {push, 0}}, {"live", true}};
    if (live == "top" && i == n - 1) blk["boundary"].push_back({{"edge", "top"}, {"force", {push, 0}}, {"live", true}});
    bodies.push_back(blk);
    contacts.push_back({{"slave", name + ".bottom"},
                        {"master", i == 0 ? "ground.top" : "b" + std::to_string(i) + ".top"},
                        {"friction", {{"coefficient", mu}}}});
  }
  return {{"name", "column"},
          {"model", {{"gravity", {0, -10}}}},
          {"bodies", bodies},
          {"contacts", contacts},
          {"collapse", json::object()}};
}

// The bracket [held, failed] holds the exact value, and is tolerance-narrow around it.
void expect_bracket(const CollapseResult& c, double exact) {
  EXPECT_EQ(c.verdict, "collapse") << c.words;
  EXPECT_LE(c.held, exact * (1 + 1e-9)) << c.words;
  EXPECT_GE(c.failed, exact * (1 - 1e-9)) << c.words;
  EXPECT_LE(c.failed - c.held, c.tolerance * c.held * (1 + 1e-9)) << c.words;
  EXPECT_NEAR(0.5 * (c.held + c.failed), exact, 1e-3 * exact) << c.words;
}

const JointMotion* joint(const Mechanism& m, const std::string& pair) {
  for (const auto& j : m.joints)
    if (j.pair == pair) return &j;
  return nullptr;
}

}  // namespace

// The column overturns about the base's toe: lambda_c = b / (n h) = 1/3; the three blocks turn as one about (1, 0),
// and the only joint that moves is the base's, a hinge at its toe.
TEST(Collapse, AColumnUnderAHorizontalBodyForceOverturnsAboutItsBaseToe) {
  const Result r = contact::testing::run(column(3, 1.0, 1.0, 0.8, "body"));
  ASSERT_TRUE(r.converged) << r.message;
  const CollapseResult& c = r.collapse;
  ASSERT_TRUE(c.analysed);
  expect_bracket(c, 1.0 / 3.0);
  EXPECT_NEAR(c.statics_bound, 1.0 / 3.0, 1e-9);
  // The mechanism is the elastic solution's own (its contact set at the last held state: the base bears at its toe
  // only), made exact; here the rigid blocks' statics finds the same one.
  EXPECT_EQ(c.mechanism.source, "elastic") << c.mechanism.check;
  EXPECT_EQ(c.statics_mechanism.source, "statics");
  EXPECT_EQ(c.statics_mechanism.words, c.mechanism.words);
  EXPECT_EQ(c.mechanism.kind, "overturning") << c.mechanism.words;
  ASSERT_EQ(c.mechanism.joints.size(), 1u) << c.mechanism.words;
  const JointMotion* base = joint(c.mechanism, "b1.bottom-ground.top");
  ASSERT_NE(base, nullptr) << c.mechanism.words;
  EXPECT_EQ(base->kind, "hinge");
  EXPECT_NEAR(base->point.x(), 1.0, 1e-12);
  EXPECT_NEAR(base->point.y(), 0.0, 1e-12);
  ASSERT_EQ(c.mechanism.bodies.size(), 3u);
  for (const auto& b : c.mechanism.bodies) {
    EXPECT_LT(b.omega, 0.0) << b.body << " turns clockwise";
    EXPECT_NEAR((b.centre - Eigen::Vector2d(1, 0)).norm(), 0.0, 1e-9) << b.body;
  }
  // The answer is the last state that held; every held trial is a step with its multiplier, after the loading's.
  ASSERT_GE(r.step_history.size(), 2u);
  EXPECT_EQ(r.step_history.front().multiplier, 0.0);
  EXPECT_EQ(r.step_history.back().multiplier, c.held);
  for (size_t k = 1; k < r.step_history.size(); ++k)
    EXPECT_GT(r.step_history[k].multiplier, r.step_history[k - 1].multiplier);
  // The base carries the weight (30) and lambda times it sideways at the last held state.
  EXPECT_NEAR(r.steps.back().bodies[0].reaction_total.y(), 30.0, 1e-6);
  EXPECT_NEAR(r.steps.back().bodies[0].reaction_total.x(), -30.0 * c.held, 1e-6);
}

// Pushed at the top, the top block (2 x 1, weight 20) slides at lambda 10 = 0.3 x 20: lambda_c = 0.6, long before
// any joint rocks (the top one at lambda = 2, the base at 2).
TEST(Collapse, AColumnPushedAtItsTopSlidesAtItsTopJoint) {
  const Result r = contact::testing::run(column(3, 2.0, 1.0, 0.3, "top"));
  ASSERT_TRUE(r.converged) << r.message;
  const CollapseResult& c = r.collapse;
  expect_bracket(c, 0.6);
  EXPECT_EQ(c.mechanism.source, "elastic") << c.mechanism.check;
  EXPECT_EQ(c.mechanism.kind, "sliding") << c.mechanism.words;
  ASSERT_EQ(c.mechanism.bodies.size(), 1u) << c.mechanism.words;
  EXPECT_EQ(c.mechanism.bodies[0].body, "b3");
  EXPECT_GT(c.mechanism.bodies[0].velocity.x(), 0.0);
  const JointMotion* top = joint(c.mechanism, "b3.bottom-b2.top");
  ASSERT_NE(top, nullptr) << c.mechanism.words;
  EXPECT_EQ(top->kind, "slides");
  EXPECT_NE(c.words.find("joint 'b3.bottom-b2.top' slides"), std::string::npos) << c.words;
}

// A block 0.5 wide and 2 tall pushed to the left (negative live load): lambda_c = b / h = 0.25, overturning about
// the left toe (0, 0), anticlockwise.
TEST(Collapse, ATallBlockPushedLeftOverturnsAboutItsLeftToe) {
  json job = {
      {"name", "tall"},
      {"model", {{"gravity", {0, -10}}}},
      {"bodies", {ground(-1, 1.5), block("tall", {{0, 0}, {0.5, 0}, {0.5, 2}, {0, 2}}, 4, 8)}},
      {"contacts", {{{"slave", "tall.bottom"}, {"master", "ground.top"}, {"friction", {{"coefficient", 0.9}}}}}},
      {"collapse", {{"tolerance", 1e-4}}}};
  job["bodies"][1]["body_force"] = {{"value", {-10, 0}}, {"live", true}};
  const Result r = contact::testing::run(job);
  ASSERT_TRUE(r.converged) << r.message;
  const CollapseResult& c = r.collapse;
  EXPECT_DOUBLE_EQ(c.tolerance, 1e-4);
  expect_bracket(c, 0.25);
  EXPECT_EQ(c.mechanism.kind, "overturning") << c.mechanism.words;
  const JointMotion* base = joint(c.mechanism, "tall.bottom-ground.top");
  ASSERT_NE(base, nullptr);
  EXPECT_EQ(base->kind, "hinge");
  EXPECT_NEAR(base->point.x(), 0.0, 1e-12);
  ASSERT_EQ(c.mechanism.bodies.size(), 1u);
  EXPECT_GT(c.mechanism.bodies[0].omega, 0.0) << "anticlockwise";
}

// A block on a slope tan(alpha) = 1/4 (its joint not along an axis), mu = 0.5, pushed sideways down the slope by
// lambda times its weight: lambda_c = (mu - tan alpha) / (1 + mu tan alpha) = 2/9, sliding down the slope.
TEST(Collapse, ABlockOnASlopeSlidesDownItAtTheFrictionLimit) {
  const double t = 0.25, c = 1 / std::sqrt(1 + t * t), s = t * c, mu = 0.5;
  // The slope falls to the right: the ground's top from (4, 1) to (-1, 2.25); the block sits on it from x = 1.
  const Eigen::Vector2d A(1.0, 2.0 - t * 1.0), d(c, -s), n(s, c);
  const Eigen::Vector2d B = A + d, C = B + 0.5 * n, D = A + 0.5 * n;
  json slope = block("slope", {{-1, 0}, {4, 0}, {4, 2.0 - t * 4.0}, {-1, 2.0 + t}}, 20, 4, 0.0);
  slope["boundary"] = json::array({{{"edge", "bottom"}, {"displacement", {{"x", 0}, {"y", 0}}}}});
  json blk = block("block", {{A.x(), A.y()}, {B.x(), B.y()}, {C.x(), C.y()}, {D.x(), D.y()}}, 8, 4);
  blk["body_force"] = {{"value", {10, 0}}, {"live", true}};
  json job = {{"name", "slope"},
              {"model", {{"gravity", {0, -10}}}},
              {"bodies", {slope, blk}},
              {"contacts", {{{"slave", "block.bottom"}, {"master", "slope.top"}, {"friction", {{"coefficient", mu}}}}}},
              {"collapse", json::object()}};
  const Result r = contact::testing::run(job);
  ASSERT_TRUE(r.converged) << r.message;
  expect_bracket(r.collapse, (mu - t) / (1 + mu * t));
  // The elastic solution's mechanism: down the slope along d, and no more (Coulomb friction does not dilate).
  const Mechanism& m = r.collapse.mechanism;
  EXPECT_EQ(m.source, "elastic") << m.check;
  EXPECT_EQ(m.kind, "sliding") << m.words;
  ASSERT_EQ(m.bodies.size(), 1u);
  EXPECT_NEAR(m.bodies[0].velocity.dot(n), 0.0, 1e-9);
  EXPECT_GT(m.bodies[0].velocity.dot(d), 0.99);
  EXPECT_NEAR(m.bodies[0].omega, 0.0, 1e-9);
  // The statics' one (associated friction) slides the same way with the flow rule's dilatancy besides: an opening
  // of mu times the slip.
  const Mechanism& associated = r.collapse.statics_mechanism;
  EXPECT_EQ(associated.source, "statics");
  EXPECT_EQ(associated.kind, "sliding") << associated.words;
  ASSERT_EQ(associated.bodies.size(), 1u);
  const Eigen::Vector2d v = associated.bodies[0].velocity;
  EXPECT_NEAR(v.dot(n) / v.dot(d), mu, 1e-6);
  EXPECT_GT(v.dot(d), 0.0);
}

// The bracket costs solves, not cut sub-steps: every trial is one increment from the last state that held, the held
// ones are the result's steps after the loading's, and without a bound from statics (the first trial given, far
// above lambda_c) the failed solves halve the bracket each time.
TEST(Collapse, EveryTrialIsOneIncrementAndTheBisectionHalvesTheBracket) {
  json job = column(3, 1.0, 1.0, 0.8, "body");
  job["collapse"] = {{"first", 0.3}, {"tolerance", 1e-3}};
  const Result r = contact::testing::run(job);
  ASSERT_TRUE(r.converged) << r.message;
  const CollapseResult& c = r.collapse;
  expect_bracket(c, 1.0 / 3.0);
  const int held = static_cast<int>(r.step_history.size()) - 1;  // after the loading's one step
  // Trials: 0.3 held; then just under the statics bound (held or not), then bisection: the bracket's width falls from
  // at most 0.0335 to 3.3e-4 in at most log2(100) + 1 halvings.
  EXPECT_LE(c.solves, 2 + 8) << c.words;
  EXPECT_GE(held, 1);
  EXPECT_LE(held, c.solves);
  EXPECT_EQ(r.step_history[1].multiplier, 0.3);
  // The capacity curve's points: at every held trial the live loads' displacement, positive (the push does
  // positive work on the column it moves) and growing with the multiplier; none where a trial did not hold. (Its
  // softening: Masonry.NearItsLimitAWallsCollapseTrials..., whose bisection holds more trials.)
  std::vector<std::pair<double, double>> curve;
  for (const auto& t : c.trials) {
    if (!t.held) {
      EXPECT_TRUE(std::isnan(t.displacement)) << t.multiplier;
      continue;
    }
    EXPECT_GT(t.displacement, 0.0) << t.multiplier;
    curve.emplace_back(t.multiplier, t.displacement);
  }
  std::sort(curve.begin(), curve.end());
  ASSERT_GE(curve.size(), 2u) << c.words;
  // From the dead loads' state (multiplier 0) the live loads do positive work on what they add.
  ASSERT_TRUE(std::isfinite(c.start_displacement)) << c.words;
  EXPECT_GT(curve.front().second, c.start_displacement);
  for (size_t k = 1; k < curve.size(); ++k) EXPECT_GT(curve[k].second, curve[k - 1].second) << curve[k].first;
}

// The thrust at the last held state is statics: the joint under k blocks of the column (unit blocks of weight 10
// each, pushed by lambda 10 per block at their mid-heights) carries N = 10 k, and the push's moment about the
// joint's middle is 10 lambda (0.5 + 1.5 + ...) = 5 lambda k^2, so its centre of pressure lies at x = 0.5 +
// lambda k / 2 on it: 0.5 + 1.5 lambda at the base, whatever the blocks' elasticity (any equilibrium's). At the
// collapse (1/3) the base's reaches the toe: the hinge of the mechanism.
TEST(Collapse, TheThrustAtTheLastHeldStateIsTheColumnsStatics) {
  const Result r = contact::testing::run(column(3, 1.0, 1.0, 0.8, "body"));
  ASSERT_TRUE(r.converged) << r.message;
  const CollapseResult& c = r.collapse;
  ASSERT_EQ(c.thrust.size(), 3u);
  for (int k = 3; k >= 1; --k) {  // the pairs in the job's order: the base (3 blocks above), then up
    const auto& t = c.thrust[static_cast<size_t>(3 - k)];
    ASSERT_TRUE(t.point.allFinite()) << t.pair;
    EXPECT_NEAR(t.force, 10.0 * k, 1e-8 * 10 * k) << t.pair;
    EXPECT_NEAR(t.point.x(), 0.5 + c.held * k / 2.0, 1e-7) << t.pair;
    EXPECT_NEAR(t.point.y(), 3.0 - k, 1e-12) << t.pair;
    EXPECT_NEAR(t.eccentricity, c.held * k, 1e-6) << t.pair;
  }
  const JointMotion* hinge = joint(c.mechanism, c.thrust[0].pair);
  ASSERT_NE(hinge, nullptr);
  EXPECT_NEAR((hinge->point - Eigen::Vector2d(1.0, 0.0)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(c.thrust[0].point.x(), 1.0, 1e-3);  // at the toe, to the bracket's width
}

// A job whose live loads only press the joints shut has no collapse: statics carries any multiple, and the trial
// at max_multiplier holds.
TEST(Collapse, LoadsThatPressTheJointsShutHoldUpToTheMaximum) {
  json job = column(2, 1.0, 1.0, 0.5, "body");
  for (auto& b : job["bodies"])
    if (b.contains("body_force")) b["body_force"]["value"] = {0, -10};  // more weight, not a push
  job["collapse"] = {{"max_multiplier", 100}};
  const Result r = contact::testing::run(job);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.collapse.verdict, "holds") << r.collapse.words;
  EXPECT_TRUE(std::isinf(r.collapse.statics_bound));
  EXPECT_EQ(r.collapse.held, 100.0);
  EXPECT_LE(r.collapse.solves, 2);
}

// The result file keeps the verdict, the bracket, the mechanism and the multiplier of every step.
TEST(Collapse, TheResultFileKeepsTheVerdictTheMechanismAndTheCapacityCurve) {
  const json job = column(3, 1.0, 1.0, 0.8, "body");
  const Problem problem = parse_or_fail(job);
  const Result r = contact::testing::solve_quietly(problem);
  ASSERT_TRUE(r.converged) << r.message;
  const std::string path = (std::filesystem::temp_directory_path() / "collapse_column.h5").string();
  io::write_result(path, problem, r);
  const io::ResultFile f = io::read_result(path);
  std::filesystem::remove(path);
  std::filesystem::remove(std::filesystem::path(path).replace_extension(".xmf"));
  const CollapseResult& c = f.collapse;
  ASSERT_TRUE(c.analysed);
  EXPECT_EQ(c.verdict, r.collapse.verdict);
  EXPECT_EQ(c.held, r.collapse.held);
  EXPECT_EQ(c.failed, r.collapse.failed);
  EXPECT_EQ(c.statics_bound, r.collapse.statics_bound);
  EXPECT_EQ(c.solves, r.collapse.solves);
  EXPECT_EQ(c.words, r.collapse.words);
  EXPECT_EQ(c.mechanism.kind, "overturning");
  ASSERT_EQ(c.mechanism.bodies.size(), 3u);
  EXPECT_EQ(c.mechanism.bodies[2].body, "b3");
  EXPECT_EQ(c.mechanism.bodies[2].centre, r.collapse.mechanism.bodies[2].centre);
  ASSERT_EQ(c.mechanism.joints.size(), 1u);
  EXPECT_EQ(c.mechanism.joints[0].kind, "hinge");
  EXPECT_EQ(c.mechanism.source, "elastic");
  EXPECT_EQ(c.mechanism.check, r.collapse.mechanism.check);
  EXPECT_EQ(c.statics_mechanism.source, "statics");
  EXPECT_EQ(c.statics_mechanism.words, r.collapse.statics_mechanism.words);
  ASSERT_EQ(c.statics_mechanism.bodies.size(), 3u);
  ASSERT_EQ(f.step_history.multiplier.size(), r.step_history.size());
  EXPECT_EQ(f.step_history.multiplier.back(), r.collapse.held);
  EXPECT_EQ(f.steps.back().multiplier, r.collapse.held);
  ASSERT_EQ(c.trials.size(), r.collapse.trials.size());
  EXPECT_EQ(c.start_displacement, r.collapse.start_displacement);
  for (size_t k = 0; k < c.trials.size(); ++k) {
    EXPECT_EQ(c.trials[k].held, r.collapse.trials[k].held);
    if (c.trials[k].held)
      EXPECT_EQ(c.trials[k].displacement, r.collapse.trials[k].displacement);
    else
      EXPECT_TRUE(std::isnan(c.trials[k].displacement));
  }
}

// A plain job (no collapse analysis) whose loads no equilibrium carries gets the statics' verdict, not the generic
// text: gravity pointing up lifts the column off (lift-off), a forgotten contact leaves blocks held by nothing
// (unsupported).
TEST(Collapse, AFailedStepIsJudgedByStatics) {
  json up = column(3, 1.0, 1.0, 0.8, "none");
  up.erase("collapse");
  up["model"]["gravity"] = {0, 10};
  const Result lifted = contact::testing::run(up);
  ASSERT_FALSE(lifted.converged);
  EXPECT_EQ(lifted.collapse.verdict, "no_equilibrium") << lifted.message;
  EXPECT_EQ(lifted.collapse.mechanism.kind, "lift-off") << lifted.message;
  EXPECT_NE(lifted.message.find("the wrong way"), std::string::npos) << lifted.message;
  EXPECT_EQ(lifted.message.find("try smaller load steps"), std::string::npos) << lifted.message;

  json forgot = column(3, 1.0, 1.0, 0.8, "none");
  forgot.erase("collapse");
  forgot["contacts"].erase(1);  // b2 on b1
  const Result fell = contact::testing::run(forgot);
  ASSERT_FALSE(fell.converged);
  EXPECT_EQ(fell.collapse.verdict, "no_equilibrium") << fell.message;
  EXPECT_EQ(fell.collapse.mechanism.kind, "unsupported") << fell.message;
  EXPECT_NE(fell.message.find("bodies 'b2', 'b3' translate along (0, -1) as one"), std::string::npos) << fell.message;
}

// With the collapse analysis, loads that fail before the multiplier rises are the dead loads' failure.
TEST(Collapse, DeadLoadsThatFailAreNamedSo) {
  json job = column(2, 1.0, 1.0, 0.8, "body");
  job["model"]["gravity"] = {0, 10};
  const Result r = contact::testing::run(job);
  ASSERT_FALSE(r.converged);
  EXPECT_EQ(r.collapse.verdict, "dead_loads_fail") << r.message;
  EXPECT_NE(r.message.find("no equilibrium by statics"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("of the dead loads"), std::string::npos) << r.message;
  // (Lifted whole or tipped about a corner as it lifts: at a bound of 0 every mechanism the loads move is one.)
  EXPECT_TRUE(r.collapse.mechanism.kind == "lift-off" || r.collapse.mechanism.kind == "overturning")
      << r.collapse.mechanism.words;
}

// Live loads and the collapse section agree, or the job is refused where it is wrong.
TEST(Collapse, LiveLoadsAndTheCollapseSectionAreValidated) {
  auto errors_of = [](const json& job) {
    const auto parsed = job::parse(job);
    return parsed.ok() ? std::string() : job::format_errors(parsed.errors);
  };
  json no_collapse = column(2, 1.0, 1.0, 0.8, "body");
  no_collapse.erase("collapse");
  EXPECT_NE(errors_of(no_collapse).find("/bodies/1/body_force/live: a live load is raised by a collapse analysis"),
            std::string::npos)
      << errors_of(no_collapse);

  json no_live = column(2, 1.0, 1.0, 0.8, "none");
  EXPECT_NE(errors_of(no_live).find("/collapse: a collapse analysis raises the live loads, and no load is live"),
            std::string::npos)
      << errors_of(no_live);

  json on_support = column(2, 1.0, 1.0, 0.8, "body");
  on_support["bodies"][0]["boundary"][0]["live"] = true;
  EXPECT_NE(errors_of(on_support).find("/bodies/0/boundary/0/live: live marks a load"), std::string::npos)
      << errors_of(on_support);

  json with_history = column(2, 1.0, 1.0, 0.8, "top");
  with_history["bodies"][2]["boundary"][0]["history"] = {1};
  EXPECT_NE(errors_of(with_history).find("/bodies/2/boundary/0/live: a live load follows the collapse multiplier"),
            std::string::npos)
      << errors_of(with_history);

  json bad = column(2, 1.0, 1.0, 0.8, "body");
  bad["collapse"] = {{"tolerance", 0.9}, {"max_solves", 1}, {"colour", "red"}};
  const std::string e = errors_of(bad);
  EXPECT_NE(e.find("/collapse/tolerance"), std::string::npos) << e;
  EXPECT_NE(e.find("/collapse/max_solves"), std::string::npos) << e;
  EXPECT_NE(e.find("colour"), std::string::npos) << e;

  // The normalized job shows the defaults.
  const Problem p = parse_or_fail(column(2, 1.0, 1.0, 0.8, "body"));
  EXPECT_EQ(p.normalized["collapse"]["tolerance"], 1e-3);
  EXPECT_EQ(p.normalized["collapse"]["max_solves"], 60);
  EXPECT_TRUE(p.collapse.enabled);
  EXPECT_TRUE(p.bodies[1].body_force_live);
}

// The progress names each solve of the load path in its own words (not an iteration): the loading's steps that held,
// then every trial with its multiplier and whether it held, as many as the trial solves.
TEST(Collapse, TheProgressReportsEveryLoadStepAndTrialAsTheyEnd) {
  struct Recorder : Observer {
    std::vector<LoadStepReport> reports;
    int iterations = 0;
    void on_load_step(const LoadStepReport& r) override { reports.push_back(r); }
    void on_iteration(const IterationReport&) override { ++iterations; }
  } recorder;
  json job = column(3, 1.0, 1.0, 0.8, "body");
  job["collapse"] = {{"first", 0.3}};
  job["loading"] = {{"steps", 2}};
  const Problem problem = parse_or_fail(job);
  CancelToken cancel;
  const Result r = solve(problem, recorder, cancel);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_EQ(recorder.reports.size(), 2u + static_cast<size_t>(r.collapse.solves));
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(recorder.reports[k].kind, LoadStepReport::Kind::held);
    EXPECT_EQ(recorder.reports[k].step, k + 1);
    EXPECT_EQ(recorder.reports[k].steps, 2);
    EXPECT_DOUBLE_EQ(recorder.reports[k].load_factor, 0.5 * (k + 1));
  }
  int iterations = 0;
  for (size_t i = 0; i < recorder.reports.size(); ++i) {
    const LoadStepReport& t = recorder.reports[i];
    iterations += t.iterations;
    if (i < 2) continue;
    const CollapseResult::Trial& trial = r.collapse.trials[i - 2];
    EXPECT_EQ(t.kind, LoadStepReport::Kind::trial);
    EXPECT_EQ(t.multiplier, trial.multiplier);
    EXPECT_EQ(t.held, trial.held);
    EXPECT_EQ(t.iterations, trial.iterations);
  }
  // Every iteration belongs to one of them.
  EXPECT_EQ(iterations, recorder.iterations);
  EXPECT_EQ(iterations, r.iterations);
}

// Every solver brackets the same limit, and the last held states agree: the direct and the iterative interface
// solvers and the monolithic reference (an independent method) on the overturning column, the last held state's
// displacements to 1e-8 of their largest.
TEST(Collapse, EverySolverBracketsTheSameLimitAndAgreesOnTheLastHeldState) {
  std::vector<Result> runs;
  for (const json& solver : {json{{"interface", {{"solver", "direct"}}}},
                             json{{"interface", {{"solver", "iterative"}}}}, json{{"method", "monolithic"}}}) {
    json job = column(3, 1.0, 1.0, 0.8, "body");
    job["solver"] = solver;
    runs.push_back(contact::testing::run(job));
    ASSERT_TRUE(runs.back().converged) << solver.dump() << ": " << runs.back().message;
    expect_bracket(runs.back().collapse, 1.0 / 3.0);
  }
  const Step& reference = runs.back().steps.back();  // the monolithic reference's
  for (size_t k = 0; k + 1 < runs.size(); ++k) {
    EXPECT_EQ(runs[k].collapse.held, runs.back().collapse.held);
    const Step& s = runs[k].steps.back();
    for (size_t a = 0; a < s.bodies.size(); ++a) {
      const double scale = contact::testing::max_abs(reference.bodies[a].displacement);
      EXPECT_LE(contact::testing::max_abs(s.bodies[a].displacement - reference.bodies[a].displacement),
                1e-8 * std::max(scale, 1e-300))
          << "solver " << k << ", body " << s.bodies[a].name;
    }
  }
}
