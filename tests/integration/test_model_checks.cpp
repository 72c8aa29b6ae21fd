// Models that are wrong say so (issue 49, items 1 and 2; check/initial_gaps.hpp, check/large_motion.hpp): the
// mistakes of surveyed or hand-built geometry get a warning with the pair or the body, its pointer and the figure;
// the correct jobs get none. The figures the warnings carry come from the drawing (the overlap a stone drawn 0.1 mm
// too long makes is 0.1 mm; a voussoir turned by delta overlaps its neighbour by R delta at radius R).
#include "check/initial_gaps.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace contact;
using contact::testing::example;
using contact::testing::parse_or_fail;
using nlohmann::json;

namespace {

job::ParseResult parse_job(const json& job, bool strict = false) {
  job::Limits limits;
  limits.mesh_directory = std::string(CONTACT_SOURCE_DIR) + "/api/examples";
  limits.strict = strict;
  return job::parse(job, limits);
}

std::string listed(const std::vector<Warning>& warnings) {
  std::string out;
  for (const auto& w : warnings) out += w.pointer + ": " + w.message + "\n";
  return out;
}

// Three stacked blocks on a clamped base under their weight (kN, m: E of concrete 2.5e7 kN/m^2), Coulomb joints:
// the top block lifted by `lift` (negative: drawn into the block below).
json stack(double E = 2.5e7, double lift = 0.0) {
  auto block = [&](const std::string& name, double y0, double y1) {
    return json{{"name", name},
                {"material", {{"E", E}, {"nu", 0.2}}},
                {"mesh", {{"block", {{"corners", {{0, y0}, {1, y0}, {1, y1}, {0, y1}}}, {"nx", 8}, {"ny", 4}}}}},
                {"body_force", {0, -25e3}}};
  };
  json base = block("base", 0, 0.5);
  base["boundary"] = json::array({{{"edge", "bottom"}, {"displacement", {{"x", 0}, {"y", 0}}}}});
  return json{{"name", "stack"},
              {"bodies", {base, block("b1", 0.5, 1.0), block("b2", 1.0 + lift, 1.5 + lift)}},
              {"contacts",
               {{{"slave", "b1.bottom"}, {"master", "base.top"}, {"friction", {{"coefficient", 0.6}}}},
                {{"slave", "b2.bottom"}, {"master", "b1.top"}, {"friction", {{"coefficient", 0.6}}}}}}};
}

// A semicircular arch of n voussoirs (radii 4.5 .. 5) on two clamped springers, each voussoir a block between two
// radial joints with arc edges; voussoir `turned` spans delta (radians) more at its end, into its neighbour.
json arch(int n, int turned = -1, double delta = 0.0) {
  const double r0 = 4.5, r1 = 5.0, pi = std::acos(-1.0);
  auto at = [](double r, double t) { return json{r * std::cos(t), r * std::sin(t)}; };
  json bodies = json::array(), contacts = json::array();
  for (int k = 0; k < n; ++k) {
    const double a = pi - pi * k / n, b = pi - pi * (k + 1) / n - (k == turned ? delta : 0.0);
    // Counter-clockwise: bottom the intrados (a to b), right the joint at b, top the extrados, left the joint at a.
    json corners = {at(r0, a), at(r0, b), at(r1, b), at(r1, a)};
    json block = {{"corners", corners},
                  {"nx", 6},
                  {"ny", 3},
                  {"edges",
                   {{"bottom", {{"arc", {{"center", {0, 0}}, {"radius", r0}}}}},
                    {"top", {{"arc", {{"center", {0, 0}}, {"radius", r1}}}}}}}};
    json body = {{"name", "v" + std::to_string(k)},
                 {"material", {{"E", 1e7}, {"nu", 0.2}}},
                 {"mesh", {{"block", block}}},
                 {"body_force", {0, -22}}};
    if (k == 0) body["boundary"] = json::array({{{"edge", "left"}, {"displacement", {{"x", 0}, {"y", 0}}}}});
    if (k == n - 1) body["boundary"] = json::array({{{"edge", "right"}, {"displacement", {{"x", 0}, {"y", 0}}}}});
    bodies.push_back(body);
    if (k > 0)
      contacts.push_back({{"slave", "v" + std::to_string(k) + ".left"},
                          {"master", "v" + std::to_string(k - 1) + ".right"},
                          {"friction", {{"coefficient", 0.6}}}});
  }
  return json{{"name", "arch"}, {"bodies", bodies}, {"contacts", contacts}};
}

}  // namespace

TEST(ModelChecks, NoExampleGetsAWarning) {
  const std::string dir = std::string(CONTACT_SOURCE_DIR) + "/api/examples";
  int jobs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    const auto parsed = parse_job(example(entry.path().filename().string()));
    ASSERT_TRUE(parsed.ok()) << entry.path();
    EXPECT_TRUE(parsed.warnings.empty()) << entry.path() << "\n" << listed(parsed.warnings);
    EXPECT_TRUE(parsed.problem->normalized.at("warnings").empty()) << entry.path();
    ++jobs;
  }
  EXPECT_GE(jobs, 20);
}

TEST(ModelChecks, ACorrectStackSolvesWithoutAWarningBeforeOrAfter) {
  const Result r = contact::testing::run(stack());
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_TRUE(r.warnings.empty()) << listed(r.warnings);
}

// A block drawn 5 mm into the block below: an overlap of 5 mm over all 9 nodes of the joint, at its pair.
TEST(ModelChecks, ABlockDrawnIntoTheOneBelowIsAnOverlapOfItsPair) {
  const auto parsed = parse_job(stack(2.5e7, -0.005));
  ASSERT_TRUE(parsed.ok());
  ASSERT_EQ(parsed.warnings.size(), 1u) << listed(parsed.warnings);
  const Warning& w = parsed.warnings[0];
  EXPECT_EQ(w.pointer, "/contacts/1");
  EXPECT_NE(w.message.find("'b2.bottom-b1.top' overlap by up to 0.005 "), std::string::npos) << w.message;
  EXPECT_NE(w.message.find("over 9 of its 9 nodes"), std::string::npos) << w.message;
  EXPECT_NE(w.message.find("\"fit\": \"interference\""), std::string::npos) << w.message;
  // The normalized copy lists it; declared, it is none.
  ASSERT_EQ(parsed.problem->normalized.at("warnings").size(), 1u);
  EXPECT_EQ(parsed.problem->normalized["warnings"][0]["pointer"], "/contacts/1");
  json declared = stack(2.5e7, -0.005);
  declared["contacts"][1]["fit"] = "interference";
  EXPECT_TRUE(parse_job(declared).warnings.empty());
  json clearance = stack(2.5e7, -0.005);
  clearance["contacts"][1]["fit"] = "clearance";
  ASSERT_EQ(parse_job(clearance).warnings.size(), 1u);
}

// A block drawn 1 cm above its support: the pair is open everywhere (1 cm), and after the solve the block has fallen
// 1 cm as a rigid body, 0.9 % of its size (1.118): both said, the second naming the body.
TEST(ModelChecks, ABlockDrawnAboveItsSupportIsOpenAndFallsAsARigidBody) {
  const auto parsed = parse_job(stack(2.5e7, 0.01));
  ASSERT_EQ(parsed.warnings.size(), 1u) << listed(parsed.warnings);
  EXPECT_EQ(parsed.warnings[0].pointer, "/contacts/1");
  EXPECT_NE(parsed.warnings[0].message.find("do not touch: the gap is 0.01 "), std::string::npos);
  const Result r = contact::testing::run(stack(2.5e7, 0.01));
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_EQ(r.warnings.size(), 2u) << listed(r.warnings);
  EXPECT_EQ(r.warnings[1].pointer, "/bodies/2");
  EXPECT_NE(r.warnings[1].message.find("body 'b2' is held by its contacts alone and moved as a rigid body by 0.01"),
            std::string::npos)
      << r.warnings[1].message;
  // Declared a clearance: no warning before; the fall is still said.
  json declared = stack(2.5e7, 0.01);
  declared["contacts"][1]["fit"] = "clearance";
  EXPECT_TRUE(parse_job(declared).warnings.empty());
}

// E = 25 where the units need 2.5e7: displacements a thousand times the bodies' sizes. Every body is named, the
// answer is the same as without the check (a warning never changes it) and the exit stays converged.
TEST(ModelChecks, AModulusInTheWrongUnitsNamesEveryBodyThatMovesFar) {
  const Result r = contact::testing::run(stack(25.0));
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_EQ(r.warnings.size(), 3u) << listed(r.warnings);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(r.warnings[static_cast<size_t>(a)].pointer, "/bodies/" + std::to_string(a));
    EXPECT_NE(r.warnings[static_cast<size_t>(a)].message.find("small-displacement"), std::string::npos);
  }
  // Linear: the displacements scale with 1 / E exactly as the correct job's.
  const Result right = contact::testing::run(stack());
  ASSERT_TRUE(right.converged);
  const double ratio = r.steps.back().bodies[2].displacement.cwiseAbs().maxCoeff() /
                       right.steps.back().bodies[2].displacement.cwiseAbs().maxCoeff();
  EXPECT_NEAR(ratio, 1e6, 1e-3 * 1e6);
}

// Strict: the warning before the solve is an error at its pointer; after it, the run fails with its steps kept.
TEST(ModelChecks, AStrictJobTakesEveryWarningAsAnError) {
  const auto refused = parse_job(stack(2.5e7, -0.005), /*strict=*/true);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.errors[0].pointer, "/contacts/1");
  json strict = stack(2.5e7, -0.005);
  strict["strict"] = true;
  EXPECT_FALSE(parse_job(strict).ok());
  json units = stack(25.0);
  units["strict"] = true;
  const Result r = contact::testing::run(units);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.stop_reason, StopReason::error);
  EXPECT_EQ(r.message.rfind("strict: /bodies/0: body 'base' moves by up to", 0), 0u) << r.message;
  EXPECT_EQ(r.steps.size(), 1u);  // the answer is kept
}

// The shrink fit's interference (gap.constant -0.6667 on arcs drawn at one radius): declared, no warning; the
// declaration taken away, one per pair with the interference as the overlap at every node it carries.
TEST(ModelChecks, AnInterferenceFitIsSaidUnlessDeclared) {
  json job = example("shrink_fit.json");
  EXPECT_TRUE(parse_job(job).warnings.empty());
  for (auto& c : job["contacts"]) c.erase("fit");
  const auto parsed = parse_job(job);
  ASSERT_EQ(parsed.warnings.size(), 2u) << listed(parsed.warnings);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(parsed.warnings[k].pointer, "/contacts/" + std::to_string(k));
    EXPECT_NE(parsed.warnings[k].message.find("overlap by up to 0.667 "), std::string::npos)
        << parsed.warnings[k].message;
  }
  const auto gaps = check::measure_initial_gaps(*parsed.problem);
  for (const auto& g : gaps) {
    EXPECT_NEAR(g.min_gap, -0.6667, 1e-9);
    EXPECT_NEAR(g.max_gap, -0.6667, 1e-9);
    EXPECT_EQ(g.overlapping, g.nodes);
  }
  // Declared an interference where the edges do not overlap: said too.
  json none = example("flat_patch.json");
  for (auto& c : none["contacts"]) c["fit"] = "interference";
  const auto undeclared = parse_job(none);
  ASSERT_FALSE(undeclared.warnings.empty());
  EXPECT_NE(undeclared.warnings[0].message.find("but its edges do not overlap"), std::string::npos);
}

// One stone of the masonry wall drawn 0.1 mm too long: its head joint with the next stone overlaps 0.1 mm; no other
// pair is said (its bed joints are straight and touching).
TEST(ModelChecks, AStoneDrawnATenthOfAMillimetreTooLongOverlapsItsHeadJoint) {
  json job = example("masonry_wall.json");
  json* stone = nullptr;
  for (auto& b : job["bodies"])
    if (b["name"] == "b0_0") stone = &b;
  ASSERT_NE(stone, nullptr);
  auto& corners = (*stone)["mesh"]["block"]["corners"];
  corners[1][0] = corners[1][0].get<double>() + 1e-4;
  corners[2][0] = corners[2][0].get<double>() + 1e-4;
  const auto parsed = parse_job(job);
  ASSERT_TRUE(parsed.ok());
  ASSERT_EQ(parsed.warnings.size(), 1u) << listed(parsed.warnings);
  size_t head = 0;
  for (size_t k = 0; k < job["contacts"].size(); ++k)
    if (job["contacts"][k]["slave"] == "b0_0.right") head = k;
  EXPECT_EQ(parsed.warnings[0].pointer, "/contacts/" + std::to_string(head));
  EXPECT_NE(parsed.warnings[0].message.find("overlap by up to 0.0001 "), std::string::npos)
      << parsed.warnings[0].message;
}

// Voussoirs on true arcs: the correct arch touches at every joint (its arcs measured as circles: no sag), and one
// voussoir turned by 0.01 degree overlaps its neighbour's joint by R delta, 0.87 mm at the extrados (R = 5).
TEST(ModelChecks, AVoussoirTurnedAHundredthOfADegreeOverlapsByRadiusTimesTheAngle) {
  const auto right = parse_job(arch(7));
  ASSERT_TRUE(right.ok()) << job::format_errors(right.errors);
  EXPECT_TRUE(right.warnings.empty()) << listed(right.warnings);
  const double delta = 0.01 * std::acos(-1.0) / 180.0;
  const auto turned = parse_job(arch(7, 3, delta));
  ASSERT_TRUE(turned.ok()) << job::format_errors(turned.errors);
  ASSERT_EQ(turned.warnings.size(), 1u) << listed(turned.warnings);
  EXPECT_EQ(turned.warnings[0].pointer, "/contacts/3");  // v4.left against v3.right
  const auto gaps = check::measure_initial_gaps(*turned.problem);
  // The joint's slave (v4.left) is the radial line at the nominal angle; v3's end lies delta beyond it: the overlap
  // along the slave's normal at radius r is r tan(delta). Its nodes are at 4.5, 4.667, 4.833 and 5; the last
  // projects to radius 5 / cos(delta), a hair past v3's extrados: not opposite the master, not measured.
  EXPECT_NEAR(gaps[3].max_overlap(), (5.0 - 0.5 / 3) * std::tan(delta), 1e-9 * delta);
  EXPECT_EQ(gaps[3].nodes, 3);
  EXPECT_NEAR(gaps[3].max_gap, -4.5 * std::tan(delta), 1e-9 * delta);
}

// A 1 x 1 block whose centre overhangs its support's edge (the ground ends at x = 2, the block spans 1.7 to 2.7):
// no support can hold it, yet the dual mortar's multiplier of the slave node at 2.2, whose segment reaches back over
// the ground, carries the whole weight there, and the solve converges. The check says so at the pair, with the
// overhang; the same block drawn over the ground gets no warning.
TEST(ModelChecks, ABlockOverhangingItsSupportIsSaidToLeanOnNodesPastTheMastersEnd) {
  auto job = [](double x0, int nx) {
    json ground = {{"name", "ground"},
                   {"material", {{"E", 1e5}, {"nu", 0.2}}},
                   {"mesh", {{"block", {{"corners", {{-1, -1}, {2, -1}, {2, 0}, {-1, 0}}}, {"nx", 12}, {"ny", 3}}}}},
                   {"boundary", {{{"edge", "bottom"}, {"displacement", {{"x", 0}, {"y", 0}}}}}}};
    json block = {
        {"name", "block"},
        {"material", {{"E", 1e5}, {"nu", 0.2}, {"density", 1.0}}},
        {"mesh", {{"block", {{"corners", {{x0, 0}, {x0 + 1, 0}, {x0 + 1, 1}, {x0, 1}}}, {"nx", nx}, {"ny", 4}}}}}};
    return json{
        {"name", "overhang"},
        {"model", {{"gravity", {0, -10}}}},
        {"bodies", {ground, block}},
        {"contacts", {{{"slave", "block.bottom"}, {"master", "ground.top"}, {"friction", {{"coefficient", 0.8}}}}}}};
  };
  for (int nx : {4, 16}) {
    const Result r = contact::testing::run(job(1.7, nx));
    ASSERT_TRUE(r.converged) << r.message;  // (the discrete model holds it: that is what the warning is about)
    ASSERT_EQ(r.warnings.size(), 1u) << listed(r.warnings);
    EXPECT_EQ(r.warnings[0].pointer, "/contacts/0");
    EXPECT_NE(r.warnings[0].message.find("carries 100 % of its normal force on slave nodes past the end of its master "
                                         "edge 'ground.top' (by up to 0.2, the master's end segments 0.25 long)"),
              std::string::npos)
        << r.warnings[0].message;
  }
  const Result inside = contact::testing::run(job(0.5, 4));
  ASSERT_TRUE(inside.converged) << inside.message;
  EXPECT_TRUE(inside.warnings.empty()) << listed(inside.warnings);
}
