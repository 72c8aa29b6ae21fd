// Bodies held by their contacts alone (floating bodies), force control, body forces and load steps. Every expected
// number comes from mechanics: equilibrium of a free body, Hertz's formula, the linearity of the problem.
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

using namespace contact;
using nlohmann::json;
using namespace contact::testing;  // the shared helpers (support.hpp)

namespace {

// The sum of the contact forces a pair exerts on its slave body, from the equilibrium of the supports: the
// y-components of the reactions of a body.
double vertical_reaction(const BodyField& b) { return b.reaction.col(1).sum(); }

}  // namespace

TEST(Floating, FreeCylinderPressedByAForceMatchesHertzForThatForce) {
  // api/examples/hertz_force.json: the half model of a cylinder (R = 10) held only by the symmetry line and its
  // contact (translation in y free), a force P/2 on its top.
  const json job = example("hertz_force.json");
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  const Step& s = r.steps.back();
  const BodyField& cylinder = body(s, "cylinder");
  ASSERT_EQ(cylinder.free_motions, std::vector<std::string>{"translation in y"});
  const double P = -2.0 * job["bodies"][1]["boundary"][1]["force"][1].get<double>(), R = 10.0;
  // Equilibrium of the free body: its supports carry nothing vertically, the lower block's carry P/2.
  EXPECT_NEAR(vertical_reaction(cylinder), 0.0, 1e-9 * P);
  EXPECT_NEAR(vertical_reaction(body(s, "lower")), P / 2, 1e-9 * P);
  const double inv_E_star = 2 * (1 - 0.3 * 0.3) / 2.1e5;
  const double a = std::sqrt(4 * P * R * inv_E_star / M_PI), p0 = 2 * P / (M_PI * a);
  EXPECT_NEAR(hertz_half_width(s.pairs[0]), a, 0.01 * a);
  EXPECT_NEAR(s.pairs[0].pressure.maxCoeff(), p0, 0.01 * p0);
  // The cylinder sank (its rigid motion is a downward translation, no rotation).
  EXPECT_LT(cylinder.rigid_motion.y(), 0.0);
  EXPECT_NEAR(cylinder.rigid_motion.z(), 0.0, 1e-12);
}

TEST(Floating, TheAugmentedLagrangianReportsTheFloatingBodysRigidMotionAsExactContactDoes) {
  // The same job with the augmented Lagrangian: it converges to exact non-penetration, so the cylinder's rigid
  // motion (its sinking) must be the exact method's up to the updates' tolerance, not left out.
  const json job = example("hertz_force.json");
  json al = job;
  al["solver"]["enforcement"] = "augmented_lagrangian";
  const Result exact = run(job), augmented = run(al);
  ASSERT_TRUE(exact.converged) << exact.message;
  ASSERT_TRUE(augmented.converged) << augmented.message;
  const BodyField& e = body(exact.steps.back(), "cylinder");
  const BodyField& a = body(augmented.steps.back(), "cylinder");
  ASSERT_LT(e.rigid_motion.y(), 0.0);
  EXPECT_NEAR(a.rigid_motion.y(), e.rigid_motion.y(), 1e-3 * std::abs(e.rigid_motion.y()));
  EXPECT_NEAR(a.rigid_motion.z(), 0.0, 1e-12);
}

TEST(Floating, MiddleBlockHeldOnlyByItsContactsIsInEquilibrium) {
  // api/examples/stack3_floating.json: the middle block has only the symmetry condition u_x = 0.
  const Result r = run(example("stack3_floating.json"));
  ASSERT_TRUE(r.converged) << r.message;
  const Step& s = r.steps.back();
  ASSERT_EQ(s.pairs.size(), 2u);
  const double above = s.pairs[0].force, below = s.pairs[1].force;
  ASSERT_GT(above, 0.0);
  EXPECT_NEAR(above, below, 1e-10 * above);  // the block's equilibrium (flat interfaces: normal = vertical)
  EXPECT_NEAR(vertical_reaction(body(s, "bottom")), below, 1e-10 * below);
  EXPECT_NEAR(-vertical_reaction(body(s, "top")), above, 1e-10 * above);
  EXPECT_NEAR(vertical_reaction(body(s, "middle")), 0.0, 1e-10 * above);
  // The same problem with the middle block clamped at its far end (api/examples/stack3.json) carries less
  // through the lower interface: the clamp takes part of the load.
  const Result clamped = run([] {
    json j = example("stack3.json");
    j.erase("solver");
    return j;
  }());
  ASSERT_TRUE(clamped.converged);
  EXPECT_LT(clamped.steps.back().pairs[1].force, below);
}

TEST(Floating, BlockUnderItsOwnWeightPressesWithItsWeight) {
  // A block 2 x 1 of weight density w resting on a clamped block: held by the symmetry line and the contact.
  json job = example("flat_patch.json");
  job.erase("solver");
  const double w = 0.078;
  job["bodies"][1]["boundary"] = {{{"edge", "left"}, {"displacement", {{"x", 0}}}}};
  job["bodies"][1]["body_force"] = {0.0, -w};
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  const double weight = w * 2.0 * 1.0;
  EXPECT_NEAR(r.steps.back().pairs[0].force, weight, 1e-10 * weight);
  EXPECT_NEAR(vertical_reaction(body(r.steps.back(), "lower")), weight, 1e-10 * weight);
}

TEST(Floating, ForceControlWithTheReactionOfADisplacementControlledRunGivesTheSameField) {
  // The punch held at one vertex: first both displacement components are prescribed there (the rotation about it
  // is free, held by the contact), then only u_x, with the reaction that run found as a point load in y
  // (translation in y free as well). The linear problem has the same solution.
  json job = example("punch_force.json");
  json& punch = job["bodies"][1];
  punch["boundary"] = {{{"vertex", "top_left"}, {"displacement", {{"x", 0}, {"y", -0.002}}}}};
  const Result displaced = run(job);
  ASSERT_TRUE(displaced.converged) << displaced.message;
  const BodyField& p1 = body(displaced.steps.back(), "punch");
  EXPECT_EQ(p1.free_motions.size(), 1u);  // the rotation about the vertex
  Eigen::Index node = -1;
  for (Eigen::Index k = 0; k < p1.reaction.rows(); ++k)
    if (p1.reaction.row(k).norm() > 0) node = k;
  ASSERT_GE(node, 0);
  const double force_y = p1.reaction(node, 1);  // the support's force on the punch becomes a load
  ASSERT_LT(force_y, 0.0);
  punch["boundary"] = {{{"vertex", "top_left"}, {"displacement", {{"x", 0}}}, {"force", {0.0, force_y}}}};
  const Result forced = run(job);
  ASSERT_TRUE(forced.converged) << forced.message;
  const BodyField& p2 = body(forced.steps.back(), "punch");
  EXPECT_EQ(p2.free_motions.size(), 2u);  // translation in y and rotation
  for (size_t b = 0; b < 2; ++b) {
    const auto& u1 = displaced.steps.back().bodies[b].displacement;
    const auto& u2 = forced.steps.back().bodies[b].displacement;
    EXPECT_LE((u1 - u2).cwiseAbs().maxCoeff(), 1e-8 * u1.cwiseAbs().maxCoeff()) << displaced.steps.back().bodies[b].name;
  }
  EXPECT_NEAR(p2.displacement(node, 1), -0.002, 1e-8 * 0.002);
}

TEST(LoadSteps, TheLastStepEqualsTheSingleStepSolveAndTheForceGrows) {
  // api/examples/seed_layers_steps.json: the paper's problem in 10 load steps.
  const json job = example("seed_layers_steps.json");
  const Result steps = run(job);
  ASSERT_TRUE(steps.converged) << steps.message;
  ASSERT_EQ(steps.steps.size(), 10u);
  json single = job;
  single.erase("loading");
  const Result one = run(single);
  ASSERT_TRUE(one.converged);
  const Step& last = steps.steps.back();
  EXPECT_EQ(last.load_factor, 1.0);
  for (size_t b = 0; b < last.bodies.size(); ++b) {
    const auto& u1 = last.bodies[b].displacement;
    const auto& u2 = one.steps.back().bodies[b].displacement;
    EXPECT_LE((u1 - u2).cwiseAbs().maxCoeff(), 1e-10 * u2.cwiseAbs().maxCoeff());
  }
  EXPECT_NEAR(last.pairs[0].force, one.steps.back().pairs[0].force, 1e-10 * last.pairs[0].force);
  for (size_t k = 0; k < steps.steps.size(); ++k) {
    EXPECT_NEAR(steps.steps[k].load_factor, 0.1 * static_cast<double>(k + 1), 1e-15);
    if (k > 0) EXPECT_GT(steps.steps[k].pairs[0].force, steps.steps[k - 1].pairs[0].force);
  }
}

TEST(LoadSteps, HertzHalfWidthGrowsLikeTheSquareRootOfTheForce) {
  // The free cylinder under 4 load steps of its force: a^2 = 4 P R / (pi E*), so a / sqrt(P) is the same at
  // every step (within the profile fit's accuracy), and each step agrees with the formula.
  json job = example("hertz_force.json");
  job["loading"] = {{"factors", {0.25, 0.5, 0.75, 1.0}}};
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_EQ(r.steps.size(), 4u);
  const double P_full = -2.0 * job["bodies"][1]["boundary"][1]["force"][1].get<double>(), R = 10.0;
  const double inv_E_star = 2 * (1 - 0.3 * 0.3) / 2.1e5;
  for (const Step& s : r.steps) {
    const double P = s.load_factor * P_full;
    const double a = std::sqrt(4 * P * R * inv_E_star / M_PI);
    EXPECT_NEAR(hertz_half_width(s.pairs[0]), a, 0.02 * a) << "load factor " << s.load_factor;
  }
}

TEST(FloatingErrors, AFloatingBodyPulledAwayFromItsContactIsNamedWithItsFreeMotion) {
  json job = example("punch_force.json");
  job["bodies"][1]["boundary"][1]["force"] = {0, 200};  // upwards: nothing holds the punch
  const Result r = run(job);
  EXPECT_EQ(r.stop_reason, StopReason::error);
  EXPECT_NE(r.message.find("body 'punch' floats (translation in y"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("'punch.bottom-block.top'"), std::string::npos) << r.message;
}

TEST(FloatingErrors, ABodyThatSlidesFreelyOnAFlatContactIsNamedAtValidation) {
  // Frictionless flat contact cannot hold a horizontal translation, whatever the loads: the job check says so
  // (before issue 23 the solve found it and blamed the loads).
  json job = example("punch_force.json");
  job["bodies"][1]["boundary"] = {{{"edge", "top"}, {"force", {0, -200}}}};
  const auto parsed = job::parse(job);
  ASSERT_FALSE(parsed.ok());
  const std::string text = job::format_errors(parsed.errors);
  EXPECT_NE(text.find("/bodies/1/boundary: body 'punch' floats (translation in x"), std::string::npos) << text;
  EXPECT_NE(text.find("translation in x (it slides along them)"), std::string::npos) << text;
}

// Issue 22, defect 11: the monolithic method returned a zero displacement (exit 0) for a floating body nothing
// holds; it must refuse every such job as the default method does, naming the body, with no result. (A punch pulled
// away from its contact is not among the cases: the monolithic active set cycles to max_iterations there, 13 s,
// and is refused only then.)
TEST(FloatingErrors, TheMonolithicMethodRefusesAnUnheldBodyLikeTheDefaultMethod) {
  // A cap held sideways at one corner and pulled off a base held at its bottom: its flat contact could hold it
  // (the job is valid), but the load pulls it away, so nothing holds it at the solution.
  const json cap = contact::testing::cap_pulled_off_base();
  const std::vector<std::pair<json, std::string>> cases = {
      {cap, "body 'cap' floats (translation in y, rotation free) and no contact holds it: its contact "
            "'cap.bottom-base.top'"}};
  for (const auto& [base_job, phrase] : cases)
    for (const std::string method : {"interface_newton", "monolithic"}) {
      json job = base_job;
      job["solver"]["method"] = method;
      const Result r = run(job);
      EXPECT_EQ(r.stop_reason, StopReason::error) << method << ": " << r.message;
      EXPECT_FALSE(r.converged) << method;
      EXPECT_TRUE(r.steps.empty()) << method << ": a refused job has no result";
      EXPECT_NE(r.message.find(phrase), std::string::npos) << method << ": " << r.message;
    }
}

TEST(FloatingErrors, AForceOnAFullyHeldEdgeAndAFloatingBodyWithTheNeumannSchemeAreValidationErrors) {
  json job = example("punch_force.json");
  job["bodies"][0]["boundary"].push_back({{"vertex", "bottom_left"}, {"force", {1, 0}}});
  auto parsed = job::parse(job);
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(job::format_errors(parsed.errors).find("/bodies/0/boundary/1: the force on vertex 'bottom_left' acts only on "
                                                   "nodes whose displacement is prescribed"),
            std::string::npos)
      << job::format_errors(parsed.errors);
  json neumann = example("stack3_floating.json");
  neumann["solver"] = {{"method", "neumann"}};
  parsed = job::parse(neumann);
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(job::format_errors(parsed.errors).find("body 'middle' floats"), std::string::npos)
      << job::format_errors(parsed.errors);
}

TEST(Floating, InterfaceNewtonWithTheCoarseProblemEqualsTheMonolithicSaddlePointSolution) {
  // The FETI-style interface problem (generalised inverses, rigid modes, equilibrium constraints) against the
  // whole saddle-point system factorised at once: independent algebra for the same discrete problem.
  for (const char* name : {"stack3_floating.json", "punch_force.json"}) {
    json job = example(name);
    job.erase("solver");
    const Result r = run(job);
    ASSERT_TRUE(r.converged) << name << ": " << r.message;
    job["solver"] = {{"method", "monolithic"}};
    const Result reference = run(job);
    ASSERT_TRUE(reference.converged) << name << ": " << reference.message;
    for (size_t b = 0; b < r.steps.back().bodies.size(); ++b) {
      const auto& u = r.steps.back().bodies[b].displacement;
      const auto& v = reference.steps.back().bodies[b].displacement;
      EXPECT_LE((u - v).cwiseAbs().maxCoeff(), 1e-8 * v.cwiseAbs().maxCoeff()) << name << " body " << b;
    }
    for (size_t k = 0; k < r.steps.back().pairs.size(); ++k) {
      const auto& p = r.steps.back().pairs[k].pressure;
      const auto& q = reference.steps.back().pairs[k].pressure;
      EXPECT_LE((p - q).cwiseAbs().maxCoeff(), 1e-8 * q.cwiseAbs().maxCoeff()) << name << " pair " << k;
    }
  }
}

namespace {

// A masonry wall one or two cells thick per brick: `rows` courses of two bricks in a running bond (odd courses: a
// half brick at each end) on a clamped base, each full brick 2 x 1 cells and each half brick 1 x 1, so that every
// node of a brick lies on a contact edge when it has bricks above and below. A pressure p on the top course.
// Dowelled: each brick held in x at its bottom-left vertex, otherwise floating. With abutments: no dowels; two
// clamped side walls and frictionless head joints hold the bricks sideways (all three rigid motions free).
constexpr double kBrick = 0.24, kCourse = 0.07, kPressure = 2.0;

json coarse_wall(int rows, bool abutments) {
  const double width = 2 * kBrick;
  auto block = [](double x0, double y0, double x1, double y1, int nx, int ny) {
    return json{{"block", {{"corners", {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}}, {"nx", nx}, {"ny", ny}}}};
  };
  json bodies = json::array(), contacts = json::array();
  bodies.push_back({{"name", "base"}, {"material", {{"E", 3e4}, {"nu", 0.2}}},
                    {"mesh", block(-0.1, -0.1, width + 0.1, 0, 8, 2)},
                    {"boundary", {{{"edge", "bottom"}, {"displacement", {{"x", 0}, {"y", 0}}}}}}});
  std::vector<std::vector<std::pair<std::string, std::array<double, 2>>>> courses;
  for (int r = 0; r < rows; ++r) {
    std::vector<double> xs = r % 2 ? std::vector<double>{0, kBrick / 2, 1.5 * kBrick, width}
                                   : std::vector<double>{0, kBrick, width};
    courses.emplace_back();
    for (size_t i = 0; i + 1 < xs.size(); ++i) {
      const std::string name = "b" + std::to_string(r) + "_" + std::to_string(i);
      const bool half = xs[i + 1] - xs[i] < 0.75 * kBrick;
      json brick = {{"name", name}, {"material", {{"E", 1e4}, {"nu", 0.2}}},
                    {"mesh", block(xs[i], r * kCourse, xs[i + 1], (r + 1) * kCourse, half ? 1 : 2, 1)},
                    {"boundary", json::array()}};
      if (!abutments) brick["boundary"].push_back({{"vertex", "bottom_left"}, {"displacement", {{"x", 0}}}});
      if (r == rows - 1) brick["boundary"].push_back({{"edge", "top"}, {"traction", {{"normal", kPressure}}}});
      bodies.push_back(brick);
      courses.back().push_back({name, {xs[i], xs[i + 1]}});
    }
  }
  for (int r = 0; r < rows; ++r)
    for (const auto& [name, x] : courses[static_cast<size_t>(r)]) {
      if (r == 0) contacts.push_back({{"slave", name + ".bottom"}, {"master", "base.top"}});
      else
        for (const auto& [below, y] : courses[static_cast<size_t>(r) - 1])
          if (std::min(x[1], y[1]) - std::max(x[0], y[0]) > 1e-9)
            contacts.push_back({{"slave", name + ".bottom"}, {"master", below + ".top"}});
    }
  if (abutments) {
    const double height = rows * kCourse;
    for (const char* side : {"left", "right"}) {
      const bool left = std::string(side) == "left";
      bodies.push_back({{"name", std::string("abutment_") + side}, {"material", {{"E", 3e4}, {"nu", 0.2}}},
                        {"mesh", left ? block(-0.1, 0, 0, height, 1, rows) : block(width, 0, width + 0.1, height, 1, rows)},
                        {"boundary", {{{"edge", "bottom"}, {"displacement", {{"x", 0}, {"y", 0}}}},
                                      {{"edge", side}, {"displacement", {{"x", 0}}}}}}});
    }
    for (const auto& course : courses) {
      contacts.push_back({{"slave", course.front().first + ".left"}, {"master", "abutment_left.right"}});
      for (size_t i = 0; i + 1 < course.size(); ++i)
        contacts.push_back({{"slave", course[i].first + ".right"}, {"master", course[i + 1].first + ".left"}});
      contacts.push_back({{"slave", course.back().first + ".right"}, {"master", "abutment_right.left"}});
    }
  }
  return {{"name", abutments ? "wall_abutments" : "wall_dowels"}, {"version", 1}, {"model", {{"plane", "strain"}}},
          {"bodies", bodies}, {"contacts", contacts}};
}

}  // namespace

TEST(Floating, BricksOneOrTwoCellsThickWithContactsAboveAndBelowAgreeWithTheMonolithicSolution) {
  // Every node of such a brick lies on a contact edge: the dofs that the generalised inverse fixes must still
  // hold all its free motions (they once were all x-components, leaving the vertical translation free), and the
  // compliance of a contact node where those dofs lie vanishes (H_AA singular although the problem is well posed).
  for (const bool abutments : {false, true}) {
    const json job = coarse_wall(4, abutments);
    const Result r = run(job);
    ASSERT_TRUE(r.converged) << job["name"] << ": " << r.message;
    json mono = job;
    mono["solver"] = {{"method", "monolithic"}};
    const Result reference = run(mono);
    ASSERT_TRUE(reference.converged) << job["name"] << ": " << reference.message;
    const Step& s = r.steps.back();
    for (size_t b = 0; b < s.bodies.size(); ++b) {
      const auto& u = s.bodies[b].displacement;
      const auto& v = reference.steps.back().bodies[b].displacement;
      EXPECT_LE((u - v).cwiseAbs().maxCoeff(), 1e-9 * v.cwiseAbs().maxCoeff()) << job["name"] << " " << s.bodies[b].name;
      if (s.bodies[b].name[0] == 'b' && s.bodies[b].name != "base")
        EXPECT_EQ(s.bodies[b].free_motions.size(), abutments ? 3u : 2u) << s.bodies[b].name;
    }
    // Every course carries the whole load through its bed joints: pressure x wall width.
    std::map<int, double> bed;
    std::map<int, std::vector<double>> head;  // head-joint forces per course
    for (const auto& p : s.pairs) {
      const int course = std::stoi(p.slave_body.substr(1, p.slave_body.find('_') - 1));
      if (p.slave_edge == "bottom") bed[course] += p.force;
      else head[course].push_back(p.force);
    }
    ASSERT_EQ(bed.size(), 4u);
    for (const auto& [course, force] : bed)
      EXPECT_NEAR(force, kPressure * 2 * kBrick, 1e-9 * kPressure * kBrick) << job["name"] << " course " << course;
    // With abutments: frictionless bed joints carry no shear, so each brick's horizontal equilibrium makes every
    // head joint of a course carry the same force; the Poisson expansion under the load closes them all.
    EXPECT_EQ(head.size(), abutments ? 4u : 0u);
    for (const auto& [course, forces] : head) {
      ASSERT_GE(forces.size(), 3u);
      EXPECT_GT(forces.front(), 0.0) << "course " << course;
      for (double f : forces) EXPECT_NEAR(f, forces.front(), 1e-9 * forces.front()) << "course " << course;
    }
  }
}

TEST(Resultants, ThePairsResultantBalancesTheAppliedForceAndTheSupportReactionsOfBothBodies) {
  // hertz_force: a cylinder pressed by 375 down onto a block, both held sideways on the symmetry line. The pair's
  // resultant on the cylinder carries the applied force (y) and balances the symmetry line's reaction (x); the
  // block receives its opposite and its supports return it. The scalar "force" (sum of normal pressures) is not
  // the resultant on a curved slave: it is larger.
  const Result r = run(example("hertz_force.json"));
  ASSERT_TRUE(r.converged) << r.message;
  const Step& s = r.steps.back();
  const PairField& pair = s.pairs.at(0);
  const BodyField& cylinder = contact::testing::body(s, "cylinder");
  const BodyField& lower = contact::testing::body(s, "lower");
  const double F = 375.0;
  EXPECT_NEAR(pair.resultant.y(), F, 1e-6 * F);
  EXPECT_NEAR(pair.resultant.x() + cylinder.reaction_total.x(), 0.0, 1e-6 * F);
  EXPECT_NEAR(cylinder.reaction_total.y(), 0.0, 1e-6 * F);
  EXPECT_LE((lower.reaction_total - pair.resultant).norm(), 1e-6 * F);  // the block's supports return it
  EXPECT_GT(pair.force, pair.resultant.norm());
  // Per condition, in the components each prescribes: y only at the bottom, which therefore carries all of it.
  ASSERT_EQ(lower.support_reactions.size(), 2u);
  EXPECT_EQ(lower.support_reactions[0].where, "left");
  EXPECT_EQ(lower.support_reactions[1].where, "bottom");
  EXPECT_EQ(lower.support_reactions[0].force.y(), 0.0);  // "left" prescribes x only
  EXPECT_NEAR(lower.support_reactions[1].force.y(), F, 1e-6 * F);
}
