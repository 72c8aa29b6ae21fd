// Job module: the examples parse, defaults are filled in, and every bad job is reported at the pointer of the
// offending value with a message that says what is wrong.
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "contact/job.hpp"

using contact::BoundaryCondition;
using contact::job::Limits;
using contact::job::parse;
using contact::job::parse_text;
using contact::job::ParseResult;
using nlohmann::json;

namespace {

std::string read_example(const std::string& name) {
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/examples/" + name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Two small blocks pressed together, restrained as in the flat patch test: a valid job that the tests below
// break in one place each.
json small_job() {
  return json::parse(R"({
    "name": "small",
    "bodies": [
      {"name": "upper", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, 0], [2, 0], [2, 1], [0, 1]], "nx": 2, "ny": 1}},
       "boundary": [{"edge": "left", "displacement": {"x": 0}},
                    {"edge": "top", "displacement": {"y": -0.001}}]},
      {"name": "lower", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, -1], [2, -1], [2, 0], [0, 0]], "nx": 2, "ny": 1}},
       "boundary": [{"edge": "left", "displacement": {"x": 0}},
                    {"edge": "bottom", "displacement": {"y": 0}}]}
    ],
    "contacts": [{"slave": "upper.bottom", "master": "lower.top"}]
  })");
}

// A unit square as an explicit mesh of two quads, with its four sides as edge sets.
json explicit_mesh() {
  return json::parse(R"({
    "nodes": [[0, 0], [1, 0], [2, 0], [0, 1], [1, 1], [2, 1]],
    "quads": [[0, 1, 4, 3], [1, 2, 5, 4]],
    "edges": {"base": [[0, 1], [1, 2]], "side": [[2, 5]], "cap": [[5, 4], [4, 3]], "wall": [[3, 0]]}
  })");
}

std::string listing(const ParseResult& r) { return contact::job::format_errors(r.errors); }

// Exactly one error, at `pointer`, whose message contains `phrase`.
void expect_only_error(const ParseResult& r, const std::string& pointer, const std::string& phrase) {
  ASSERT_EQ(r.errors.size(), 1u) << listing(r);
  EXPECT_FALSE(r.problem.has_value());
  EXPECT_EQ(r.errors[0].pointer, pointer) << listing(r);
  EXPECT_NE(r.errors[0].message.find(phrase), std::string::npos) << "missing phrase '" << phrase << "' in\n"
                                                                 << listing(r);
}

}  // namespace

// ---- valid jobs -------------------------------------------------------------------------------------------

TEST(JobExamples, EveryExampleParsesWithoutErrors) {
  for (const char* name : {"seed_layers.json", "seed_layers_curved.json", "flat_patch.json",
                           "flat_patch_nonmatching.json", "hertz.json", "stack3.json"}) {
    const std::string text = read_example(name);
    ASSERT_FALSE(text.empty()) << name;
    const ParseResult r = parse_text(text);
    EXPECT_TRUE(r.ok()) << name << ":\n" << listing(r);
    EXPECT_TRUE(r.problem.has_value()) << name;
  }
}

TEST(JobExamples, SeedLayersGivesTheMeshesConditionsAndContactIndicesItDescribes) {
  const ParseResult r = parse_text(read_example("seed_layers.json"));
  ASSERT_TRUE(r.ok()) << listing(r);
  const contact::Problem& p = *r.problem;
  EXPECT_EQ(p.name, "seed_layers");
  ASSERT_EQ(p.bodies.size(), 2u);
  for (const auto& body : p.bodies) {
    EXPECT_EQ(body.mesh.num_cells(), 32 * 8);
    EXPECT_EQ(body.mesh.num_nodes(), 33 * 9);
    EXPECT_EQ(body.mesh.edge_sets.at("bottom").size(), 32u);
    EXPECT_EQ(body.mesh.level, std::vector<int>(256, 0));
    EXPECT_DOUBLE_EQ(body.material.E, 2.1e5);
    EXPECT_DOUBLE_EQ(body.material.nu, 0.3);
    ASSERT_EQ(body.boundary.size(), 3u);
  }
  const auto& upper = p.bodies[0];
  EXPECT_EQ(upper.name, "upper");
  EXPECT_EQ(upper.boundary[0].edge, "left");
  EXPECT_EQ(upper.boundary[0].kind, BoundaryCondition::Kind::displacement);
  EXPECT_EQ(upper.boundary[0].ux, 0.0);
  EXPECT_FALSE(upper.boundary[0].uy.has_value());
  EXPECT_EQ(upper.boundary[1].uy, -0.001366);
  EXPECT_EQ(upper.boundary[2].kind, BoundaryCondition::Kind::traction);
  EXPECT_FALSE(upper.boundary[2].normal_pressure);
  EXPECT_EQ(upper.boundary[2].traction, Eigen::Vector2d::Zero());
  EXPECT_NEAR(upper.mesh.bbox_min().y(), 0.0, 1e-15);
  EXPECT_NEAR(p.bodies[1].mesh.bbox_max().y(), 0.0, 1e-15);

  ASSERT_EQ(p.contacts.size(), 1u);
  const auto& pair = p.contacts[0];
  EXPECT_EQ(pair.name, "upper.bottom-lower.top");
  EXPECT_EQ(pair.slave_body, 0);
  EXPECT_EQ(pair.slave_edge, "bottom");
  EXPECT_EQ(pair.master_body, 1);
  EXPECT_EQ(pair.master_edge, "top");
  EXPECT_TRUE(pair.gap.geometric);
  EXPECT_EQ(pair.gap.parabola_r0, 0.001);
  EXPECT_EQ(pair.gap.parabola_x0, 0.0);

  EXPECT_EQ(p.solver.method, contact::Method::neumann);
  EXPECT_FALSE(p.solver.penalty.theta.has_value());
  EXPECT_EQ(p.solver.penalty.c, 0.05);
  EXPECT_EQ(p.solver.penalty.length, 1.0);
  EXPECT_EQ(p.solver.criterion, contact::Criterion::paper);
  EXPECT_EQ(p.solver.initial_guess, contact::InitialGuess::elastic_layer);
  EXPECT_EQ(p.submitted, json::parse(read_example("seed_layers.json")));
}

TEST(JobExamples, CurvedEdgeKeepsItsCurveForRefinementAndItsNodesOnTheParabola) {
  const ParseResult r = parse_text(read_example("seed_layers_curved.json"));
  ASSERT_TRUE(r.ok()) << listing(r);
  const auto& upper = r.problem->bodies[0].mesh;
  ASSERT_EQ(upper.edge_curves.count("bottom"), 1u);
  EXPECT_EQ(upper.edge_curves.at("bottom").kind, contact::mesh::Curve::Kind::parabola);
  for (int n : upper.edge_set_nodes("bottom")) {
    const auto& x = upper.nodes[static_cast<size_t>(n)];
    EXPECT_NEAR(x.y(), 0.001 * x.x() * x.x(), 1e-14);
  }
  EXPECT_FALSE(r.problem->contacts[0].gap.parabola_r0.has_value());
}

TEST(JobDefaults, MissingFieldsGetTheirDefaultsInProblemAndNormalized) {
  const json job = small_job();
  const ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  const contact::Problem& p = *r.problem;
  EXPECT_EQ(p.model.plane, contact::Plane::strain);
  EXPECT_EQ(p.model.thickness, 1.0);
  // The defaults are fast and exact (dual mortar contact by interface Newton).
  EXPECT_EQ(p.solver.method, contact::Method::interface_newton);
  EXPECT_TRUE(p.solver.gamma_auto);
  EXPECT_EQ(p.solver.acceleration, contact::Acceleration::anderson);
  EXPECT_EQ(p.solver.anderson_depth, 10);
  EXPECT_EQ(p.solver.enforcement, contact::Enforcement::exact);
  EXPECT_EQ(p.solver.criterion, contact::Criterion::residual);
  EXPECT_EQ(p.solver.tolerance, 1e-8);
  EXPECT_EQ(p.solver.max_iterations, 2000);
  EXPECT_EQ(p.solver.threads, 0);
  EXPECT_EQ(p.contacts[0].name, "upper.bottom-lower.top");
  EXPECT_EQ(p.bodies[0].body_force, Eigen::Vector2d::Zero());

  EXPECT_EQ(p.submitted, job);
  const json& n = p.normalized;
  EXPECT_EQ(n["version"], 1);
  EXPECT_EQ(n["model"]["plane"], "strain");
  EXPECT_EQ(n["model"]["thickness"], 1.0);
  EXPECT_EQ(n["solver"]["method"], "interface_newton");
  EXPECT_EQ(n["solver"]["penalty"], json({{"c", 0.05}}));
  EXPECT_EQ(n["solver"]["gamma"], "auto");
  EXPECT_EQ(n["solver"]["tolerance"], 1e-8);
  EXPECT_EQ(n["solver"]["criterion"], "residual");
  EXPECT_EQ(n["solver"]["enforcement"], "exact");
  EXPECT_EQ(n["solver"]["max_iterations"], 2000);
  EXPECT_EQ(n["solver"]["initial_guess"], "elastic_layer");
  EXPECT_EQ(n["solver"]["threads"], 0);
  EXPECT_EQ(n["contacts"][0]["name"], "upper.bottom-lower.top");
  EXPECT_EQ(n["contacts"][0]["gap"], json({{"geometric", true}, {"constant", 0.0}}));
  EXPECT_EQ(n["bodies"][1]["body_force"], json::array({0.0, 0.0}));
  // Normalising is idempotent: the normalized document reads back to itself.
  const ParseResult again = parse(n);
  ASSERT_TRUE(again.ok()) << listing(again);
  EXPECT_EQ(again.problem->normalized, n);
}

TEST(JobDefaults, TheEnforcementDefaultFollowsTheMethodAndTheNormalizedJobSaysWhatRuns) {
  struct Case {
    json solver, adaptivity;
    const char* method;
    const char* enforcement;
  };
  const std::vector<Case> cases = {
      {json::object(), nullptr, "interface_newton", "exact"},
      {{{"method", "monolithic"}}, nullptr, "monolithic", "exact"},
      {{{"method", "neumann"}}, nullptr, "neumann", "penalty"},
      {{{"method", "robin"}}, nullptr, "robin", "penalty"},
      {{{"method", "neumann"}, {"enforcement", "augmented_lagrangian"}}, nullptr, "neumann", "augmented_lagrangian"},
      // The paper's adaptive strategy is a Neumann iteration: without a method it runs the paper's penalty scheme.
      {json::object(), {{"strategy", "paper"}}, "neumann", "penalty"},
      {json::object(), {{"strategy", "converge_then_refine"}}, "interface_newton", "exact"},
  };
  for (const auto& c : cases) {
    json job = small_job();
    job["solver"] = c.solver;
    if (!c.adaptivity.is_null()) job["adaptivity"] = c.adaptivity;
    const ParseResult r = parse(job);
    ASSERT_TRUE(r.ok()) << c.solver.dump() << ": " << listing(r);
    EXPECT_EQ(r.problem->normalized["solver"]["method"], c.method) << c.solver.dump() << c.adaptivity.dump();
    EXPECT_EQ(r.problem->normalized["solver"]["enforcement"], c.enforcement) << c.solver.dump() << c.adaptivity.dump();
  }
}

TEST(JobDefaults, ANumericGammaSwitchesOffTheAutomaticChoice) {
  json job = small_job();
  job["solver"] = {{"gamma", 0.03}};
  const ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_FALSE(r.problem->solver.gamma_auto);
  EXPECT_EQ(r.problem->solver.gamma, 0.03);
  job["solver"] = {{"gamma", "auto"}};
  EXPECT_TRUE(parse(job).problem->solver.gamma_auto);
}

TEST(JobDefaults, ThetaGivenDirectlyIsKeptAndNoCIsAdded) {
  json job = small_job();
  job["solver"] = {{"penalty", {{"theta", 1e-8}}}, {"method", "monolithic"}};
  const ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->solver.penalty.theta, 1e-8);
  EXPECT_EQ(r.problem->solver.method, contact::Method::monolithic);
  EXPECT_EQ(r.problem->normalized["solver"]["penalty"], json({{"theta", 1e-8}}));
}

TEST(JobExplicitMesh, ArraysBecomeAMeshWithOrderedEdgeSetsAndConditions) {
  json job = small_job();
  job["bodies"][0]["mesh"] = explicit_mesh();
  job["bodies"][0]["boundary"] = json::parse(
      R"([{"edge": "wall", "displacement": {"x": 0}}, {"edge": "cap", "traction": {"normal": 5}},
          {"edge": "side", "free": true}, {"edge": "base", "displacement": {"y": 0}}])");
  job["contacts"][0]["slave"] = "upper.base";
  const ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  const auto& body = r.problem->bodies[0];
  EXPECT_EQ(body.mesh.num_nodes(), 6);
  EXPECT_EQ(body.mesh.num_cells(), 2);
  EXPECT_EQ(body.mesh.level, (std::vector<int>{0, 0}));
  EXPECT_EQ(body.mesh.edge_set_nodes("cap"), (std::vector<int>{5, 4, 3}));
  EXPECT_TRUE(body.boundary[1].normal_pressure);
  EXPECT_EQ(body.boundary[1].pressure, 5.0);
  EXPECT_EQ(body.boundary[2].kind, BoundaryCondition::Kind::free);
  EXPECT_EQ(r.problem->contacts[0].slave_edge, "base");
}

TEST(JobExplicitMesh, StraightEdgesAndCornersGetNoCurveSoAFlatExplicitMeshIsItsChords) {
  // Every edge fitted by default (mesh.curves): straight runs keep their chords, and an edge round the whole
  // outline (a closed loop with four corners) is fitted piecewise between them, so no side of a flat mesh gets
  // an arc and it computes what it did before the fit existed.
  json job = small_job();
  job["bodies"][0]["mesh"] = explicit_mesh();
  job["bodies"][0]["mesh"]["edges"]["outline"] = json::parse("[[0, 1], [1, 2], [2, 5], [5, 4], [4, 3], [3, 0]]");
  job["bodies"][0]["boundary"] = {{{"edge", "wall"}, {"displacement", {{"x", 0}, {"y", 0}}}}};
  job["contacts"][0]["slave"] = "upper.base";
  const ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  const auto& mesh = r.problem->bodies[0].mesh;
  EXPECT_TRUE(mesh.edge_set_closed("outline"));
  EXPECT_TRUE(mesh.side_curves.empty());
  EXPECT_EQ(
      r.problem->normalized["bodies"][0]["mesh"]["curves"],
      json({{"base", "fitted"}, {"cap", "fitted"}, {"outline", "fitted"}, {"side", "fitted"}, {"wall", "fitted"}}));
  // A curve given for an edge is set on each of its sides, b and c from each side's ends: "cap" (nodes 5, 4, 3,
  // all at y = 1) as the parabola of a = 0 is y = 1 on both its sides.
  job["bodies"][0]["mesh"]["curves"] = {{"cap", {{"parabola", {{"a", 0.0}}}}}};
  const ParseResult p = parse(job);
  ASSERT_TRUE(p.ok()) << listing(p);
  EXPECT_EQ(p.problem->bodies[0].mesh.side_curves.size(), 2u);
  for (const auto& [side, curve] : p.problem->bodies[0].mesh.side_curves) {
    EXPECT_EQ(curve.kind, contact::mesh::Curve::Kind::parabola);
    EXPECT_DOUBLE_EQ(curve.b, 0.0);
    EXPECT_DOUBLE_EQ(curve.c, 1.0);
  }
}

TEST(JobRobustness, NonObjectDocumentsAreErrorsNotExceptions) {
  for (const json& doc : {json(nullptr), json(3), json("job"), json::array()}) {
    const ParseResult r = parse(doc);
    ASSERT_EQ(r.errors.size(), 1u) << doc.dump();
    EXPECT_EQ(r.errors[0].pointer, "");
    EXPECT_NE(r.errors[0].message.find("must be an object"), std::string::npos);
  }
}

TEST(JobRobustness, AnyLeafReplacedByAnyValueGivesErrorsNeverAnInternalFailure) {
  json with_arrays = small_job();
  with_arrays["bodies"][0]["mesh"] = explicit_mesh();
  with_arrays["bodies"][0]["boundary"] = {{{"edge", "wall"}, {"displacement", {{"x", 0}, {"y", 0}}}}};
  with_arrays["bodies"][1]["mesh"]["block"]["edges"] = {
      {"bottom", {{"arc", {{"center", {1, -5}}, {"radius", 4.123105625617661}}}}}};
  with_arrays["contacts"][0]["slave"] = "upper.base";
  with_arrays["contacts"][0]["gap"] = {{"parabola", {{"r0", 0.001}}}};
  with_arrays["solver"] = {{"penalty", {{"c", 0.1}}}, {"gamma", 0.1}};
  const json replacements[] = {
      nullptr, "x", -1, 0, 2.5, 1e300, true, json::array(), json::object(), json::array({1, 2, 3, 4, 5})};
  int tried = 0;
  for (const json& job : {small_job(), with_arrays}) {
    ASSERT_TRUE(parse(job).ok()) << listing(parse(job));
    const json leaves = job.flatten();
    for (const auto& leaf : leaves.items()) {
      const json::json_pointer at(leaf.key());
      for (const json& value : replacements) {
        json bad = job;
        bad[at] = value;
        const ParseResult r = parse(bad);
        EXPECT_EQ(r.ok(), r.problem.has_value());
        for (const auto& e : r.errors) {
          EXPECT_EQ(e.message.find("internal error"), std::string::npos)
              << leaf.key() << " = " << value.dump() << ": " << e.message;
          EXPECT_FALSE(e.message.empty());
        }
        ++tried;
      }
      // And the leaf removed altogether.
      json without = job;
      json& parent = without[at.parent_pointer()];
      if (parent.is_object())
        parent.erase(at.back());
      else
        parent.erase(static_cast<size_t>(std::stoul(at.back())));
      for (const auto& e : parse(without).errors)
        EXPECT_EQ(e.message.find("internal error"), std::string::npos) << e.message;
    }
  }
  EXPECT_GT(tried, 500);
}

// ---- bad jobs: one fault each, reported at its pointer -----------------------------------------------------

namespace {

// A row of the table below: a valid base job, a JSON Patch (RFC 6902) that puts one fault into it, and the one
// error that fault must give: its pointer and a phrase of its message.
struct BadJob {
  const char* name;  // the row's name in the test listing
  json (*base)();
  std::vector<json> patch;
  std::string pointer;
  std::string phrase;
};

void PrintTo(const BadJob& row, std::ostream* os) { *os << row.name << ": " << json(row.patch).dump(); }

json add(const std::string& pointer, json value) {
  return {{"op", "add"}, {"path", pointer}, {"value", std::move(value)}};
}
json replace(const std::string& pointer, json value) {
  return {{"op", "replace"}, {"path", pointer}, {"value", std::move(value)}};
}
json remove(const std::string& pointer) { return {{"op", "remove"}, {"path", pointer}}; }

// The small job with the upper block as the explicit mesh, held at its wall, in contact along its base.
json upper_explicit() {
  json job = small_job();
  job["bodies"][0]["mesh"] = explicit_mesh();
  job["bodies"][0]["boundary"] = {{{"edge", "wall"}, {"displacement", {{"x", 0}, {"y", 0}}}}};
  job["contacts"][0]["slave"] = "upper.base";
  return job;
}

std::vector<BadJob> bad_jobs() {
  return {
      // Bodies: materials, block meshes, fields.
      {"MissingMaterialIsReportedWhereItBelongs",
       small_job,
       {remove("/bodies/0/material")},
       "/bodies/0/material",
       "required field 'material' is missing"},
      {"ZeroYoungsModulusIsRejectedAsNotPositive",
       small_job,
       {replace("/bodies/1/material/E", 0)},
       "/bodies/1/material/E",
       "E = 0 must be positive"},
      {"NuOfOneHalfIsRejectedAtItsPointer",
       small_job,
       {replace("/bodies/1/material/nu", 0.5)},
       "/bodies/1/material/nu",
       "nu = 0.5 is outside (-1, 0.5)"},
      {"NuOfMinusOneIsRejectedAtItsPointer",
       small_job,
       {replace("/bodies/0/material/nu", -1)},
       "/bodies/0/material/nu",
       "nu = -1 is outside (-1, 0.5)"},
      {"WrongTypeIsNamed",
       small_job,
       {replace("/bodies/0/material/nu", "0.3")},
       "/bodies/0/material/nu",
       "nu must be a number, got string"},
      {"ZeroElementsAcrossABlockAreRejected",
       small_job,
       {replace("/bodies/0/mesh/block/nx", 0)},
       "/bodies/0/mesh/block/nx",
       "nx = 0 must be at least 1"},
      {"FractionalElementCountIsNotAnInteger",
       small_job,
       {replace("/bodies/0/mesh/block/nx", 2.5)},
       "/bodies/0/mesh/block/nx",
       "nx must be an integer, got 2.5"},
      {"UnknownFieldInsideABlockIsRejected",
       small_job,
       {add("/bodies/1/mesh/block/nz", 3)},
       "/bodies/1/mesh/block/nz",
       "unknown field 'nz' in block"},
      {"ArcRadiusInconsistentWithTheCornersIsReportedAtTheArc",
       small_job,
       {add("/bodies/0/mesh/block/edges", {{"bottom", {{"arc", {{"center", {1, 5}}, {"radius", 4}}}}}})},
       "/bodies/0/mesh/block/edges/bottom/arc",
       "not at the radius 4"},
      {"ParabolaWithEqualXEndsIsReportedAtTheParabola",
       small_job,
       {add("/bodies/0/mesh/block/edges", {{"left", {{"parabola", {{"a", 0.1}}}}}})},
       "/bodies/0/mesh/block/edges/left/parabola",
       "different x"},
      {"GradingTowardsBothTopAndBottomIsRejected",
       small_job,
       {add("/bodies/0/mesh/block/grading", {{"top", 4}, {"bottom", 4}})},
       "/bodies/0/mesh/block/grading",
       "grading towards both bottom and top"},
      {"ClockwiseCornersAreRejectedBeforeMeshing",
       small_job,
       {replace("/bodies/0/mesh/block/corners", {{0, 0}, {0, 1}, {2, 1}, {2, 0}})},
       "/bodies/0/mesh/block/corners",
       "the corners run clockwise"},

      // Explicit meshes.
      {"InvertedExplicitQuadIsReportedOnTheMesh",
       upper_explicit,
       {replace("/bodies/0/mesh/quads/1", {1, 4, 5, 2})},  // clockwise
       "/bodies/0/mesh",
       "cell 1 is inverted"},
      // Quad 1 has four distinct node indices, but nodes 5 and 2 coincide: it collapses to a triangle.
      {"DegenerateExplicitQuadIsReportedOnTheMesh",
       upper_explicit,
       {replace("/bodies/0/mesh", json::parse(R"({
          "nodes": [[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [1, 1]],
          "quads": [[0, 1, 2, 3], [1, 4, 5, 2]],
          "edges": {"base": [[0, 1], [1, 4]], "wall": [[3, 0]]}})"))},
       "/bodies/0/mesh",
       "cell 1 is degenerate"},
      {"EdgePairThatIsNotABoundarySideIsReportedAtTheEdgeSet",
       upper_explicit,
       {replace("/bodies/0/mesh/edges/base", {{0, 1}, {1, 4}}),  // 1-4 is shared by both quads
        replace("/contacts/0/slave", "upper.cap")},
       "/bodies/0/mesh/edges/base",
       "interior side"},
      {"ExplicitCurveOfAnUnknownEdgeListsTheMeshsEdges",
       upper_explicit,
       {add("/bodies/0/mesh/curves", {{"bse", "chords"}})},
       "/bodies/0/mesh/curves/bse",
       "'bse' is not an edge of this mesh; its edges are base, cap, side and wall"},
      {"ExplicitCurveOfAnUnknownKindNamesTheFourKinds",
       upper_explicit,
       {add("/bodies/0/mesh/curves", {{"base", "smooth"}})},
       "/bodies/0/mesh/curves/base",
       "unknown curve \"smooth\": give \"fitted\""},
      {"ExplicitArcOffTheEdgesNodesNamesTheSide",
       upper_explicit,
       {add("/bodies/0/mesh/curves", {{"cap", {{"arc", {{"center", {1, -5}}, {"radius", 6}}}}}})},
       "/bodies/0/mesh/curves/cap/arc",
       "edge 'cap': side [5, 4]: the edge's end corners are at distances"},
      {"ExplicitCurvesMustBeAnObject",
       upper_explicit,
       {add("/bodies/0/mesh/curves", "fitted")},
       "/bodies/0/mesh/curves",
       "curves must be an object"},

      // Boundary conditions.
      {"UnknownEdgeInBoundaryListsTheEdgesTheBodyHas",
       small_job,
       {replace("/bodies/1/boundary/1/edge", "botom")},
       "/bodies/1/boundary/1/edge",
       "the body has no edge 'botom'; its edges are bottom, right, top and left"},
      {"ConditionWithADisplacementAndTwoLoadsIsRejected",
       small_job,
       {add("/bodies/0/boundary/0/traction", {0, 0}), add("/bodies/0/boundary/0/force", {0, 1})},
       "/bodies/0/boundary/0",
       "give a displacement, a load (traction or force)"},
      {"ConditionWithADisplacementALoadAndFreeIsRejected",
       small_job,
       {add("/bodies/0/boundary/0/force", {0, 1}), add("/bodies/0/boundary/0/free", true)},
       "/bodies/0/boundary/0",
       "give a displacement, a load (traction or force)"},
      {"DisplacementWithoutComponentsIsRejected",
       small_job,
       {add("/bodies/0/boundary/-", {{"edge", "right"}, {"displacement", json::object()}})},
       "/bodies/0/boundary/2/displacement",
       "at least one of the components x and y"},
      {"SecondConditionOnTheSameEdgeIsRejected",
       small_job,
       {add("/bodies/0/boundary/-", {{"edge", "left"}, {"displacement", {{"y", 0}}}})},
       "/bodies/0/boundary/2/edge",
       "already has a condition at /bodies/0/boundary/0"},

      // Rigid motions left free.
      {"BodyWithoutDisplacementConditionsAndWithoutContactHasAllThreeRigidMotionsFree",
       small_job,
       {replace("/bodies/0/boundary", {{{"edge", "top"}, {"traction", {{"normal", 1.0}}}}}), remove("/contacts")},
       "/bodies/0/boundary",
       "translation in x, translation in y and rotation are free) and touches no other body"},
      // u_x = 0 along the (horizontal) bottom and u_y = 0 along the (vertical) left edge leave the rotation about
      // their common corner (0, -1) free.
      {"BodyHeldOnlyAgainstTranslationsRotatesAboutTheCornerThatNamesIt",
       small_job,
       {replace("/bodies/1/boundary", json::parse(R"([{"edge": "bottom", "displacement": {"x": 0}},
                                                      {"edge": "left", "displacement": {"y": 0}}])")),
        remove("/contacts")},
       "/bodies/1/boundary",
       "rotation about (0, -1) is free"},
      {"RigidMotionIsNotCheckedForABodyWithOtherErrors",
       small_job,
       {remove("/bodies/1/boundary/0"), replace("/bodies/1/material/E", -1)},
       "/bodies/1/material/E",
       "must be positive"},

      // Contacts.
      {"UnknownBodyInContactListsTheBodies",
       small_job,
       {replace("/contacts/0/slave", "uper.bottom")},
       "/contacts/0/slave",
       "there is no body named 'uper'; the bodies are upper and lower"},
      {"UnknownEdgeInContactIsRejected",
       small_job,
       {replace("/contacts/0/master", "lower.tip")},
       "/contacts/0/master",
       "body 'lower' has no edge 'tip'"},
      {"ContactReferenceWithoutADotIsMalformed",
       small_job,
       {replace("/contacts/0/slave", "upper")},
       "/contacts/0/slave",
       "must be \"body.edge\""},
      {"BodyCannotBeInContactWithItself",
       small_job,
       {replace("/contacts/0/master", "upper.top")},
       "/contacts/0",
       "a body cannot be in contact with itself"},
      {"SamePairTwiceIsRejected",
       small_job,
       {add("/contacts/-", {{"slave", "upper.bottom"}, {"master", "lower.top"}, {"name", "again"}})},
       "/contacts/1",
       "already given at /contacts/0"},
      {"SamePairTwiceIsRejectedWithSlaveAndMasterSwapped",
       small_job,
       {add("/contacts/-", {{"slave", "lower.top"}, {"master", "upper.bottom"}})},
       "/contacts/1",
       "slave and master swapped"},

      // The job's own fields.
      {"UnsupportedVersionIsRejected", small_job, {add("/version", 2)}, "/version", "version 2 is not supported"},
      {"UnknownTopLevelFieldIsRejectedWithASuggestion",
       small_job,
       {add("/solvr", json::object())},
       "/solvr",
       "unknown field 'solvr' in the job (did you mean 'solver'?)"},
      {"UnknownFieldNamesAreEscapedInThePointer",
       small_job,
       {add("/a~1b~0c", 1)},  // the field "a/b~c"
       "/a~1b~0c",
       "unknown field 'a/b~c'"},

      // Solver.
      {"BothThetaAndCAreRejected",
       small_job,
       {add("/solver", {{"penalty", {{"theta", 1e-7}, {"c", 0.05}}}})},
       "/solver/penalty",
       "give either theta, or c"},
      {"GammaOfTwoIsOutsideTheOpenInterval",
       small_job,
       {add("/solver", {{"gamma", 2}})},
       "/solver/gamma",
       "gamma = 2 is outside (0, 2)"},
      {"UnknownMethodListsTheChoices",
       small_job,
       {add("/solver", {{"method", "uzawa"}})},
       "/solver/method",
       "method \"uzawa\" is not one of \"neumann\", \"monolithic\", \"interface_newton\" and \"robin\""},
      // Combinations that cannot run.
      {"ExactEnforcementWithTheNeumannMethod",
       small_job,
       {add("/solver", {{"method", "neumann"}, {"enforcement", "exact"}})},
       "/solver/enforcement",
       "penalty problem"},
      {"ExactEnforcementWithTheRobinMethod",
       small_job,
       {add("/solver", {{"method", "robin"}, {"enforcement", "exact"}})},
       "/solver/enforcement",
       "penalty problem"},
      {"PaperStrategyWithTheInterfaceNewtonMethod",
       small_job,
       {add("/solver", {{"method", "interface_newton"}}), add("/adaptivity", {{"strategy", "paper"}})},
       "/solver/method",
       "needs method \"neumann\""},
      {"PaperStrategyWithExactEnforcement",
       small_job,
       {add("/solver", {{"enforcement", "exact"}}), add("/adaptivity", {{"strategy", "paper"}})},
       "/solver/enforcement",
       "must be \"penalty\""},

      // Adaptivity.
      {"AdaptivityWithAnUnknownBodyNamesTheBodies",
       small_job,
       {add("/adaptivity", {{"indicator", "fem_bem"}, {"bodies", {"lower", "middle"}}})},
       "/adaptivity/bodies/1",
       "unknown body 'middle'; the bodies are upper and lower"},
      {"AdaptivityWithAnUnknownIndicatorListsTheChoices",
       small_job,
       {add("/adaptivity", {{"indicator", "residual"}})},
       "/adaptivity/indicator",
       "\"fem_bem\""},
  };
}

}  // namespace

class JobErrorTable : public ::testing::TestWithParam<BadJob> {};

TEST_P(JobErrorTable, TheFaultIsTheOnlyErrorAtItsPointer) {
  const BadJob& row = GetParam();
  SCOPED_TRACE(json(row.patch).dump());
  const ParseResult r = parse(row.base().patch(json(row.patch)));
  EXPECT_FALSE(r.ok());
  expect_only_error(r, row.pointer, row.phrase);
}

INSTANTIATE_TEST_SUITE_P(OneFault, JobErrorTable, ::testing::ValuesIn(bad_jobs()),
                         [](const ::testing::TestParamInfo<BadJob>& info) { return std::string(info.param.name); });

// Bad jobs whose tests check more than one fault's only error: several errors, valid values beside the bad ones,
// the length of a message, a caller's limits, the text before it is parsed, or the first of the errors.

TEST(JobErrors, IntegralFloatElementCountIsAccepted) {
  json job = small_job();
  job["bodies"][0]["mesh"]["block"]["nx"] = 2.0;
  EXPECT_TRUE(parse(job).ok());
}

TEST(JobErrors, AWrongChoiceStringIsShownShortened) {
  // A hostile string in a field that takes a number or a word: the message quotes it, cut short.
  for (const char* field : {"gamma", "robin"}) {
    json job = small_job();
    const std::string huge(100000, 'x');
    if (std::string(field) == "gamma")
      job["solver"]["gamma"] = huge;
    else
      job["solver"] = {{"method", "robin"}, {"robin", {{"psi", huge}}}};
    const ParseResult r = parse(job);
    ASSERT_EQ(r.errors.size(), 1u) << listing(r);
    EXPECT_LT(r.errors[0].message.size(), 300u) << field;
    EXPECT_NE(r.errors[0].message.find("xxxx"), std::string::npos) << field;
  }
}

TEST(JobErrors, AdaptivityStopToleranceMustBeARelativeChangeBelowOne) {
  for (const double bad : {-0.1, 1.0, 2.5}) {
    json job = small_job();
    job["adaptivity"] = {{"stop_tolerance", bad}};
    expect_only_error(parse(job), "/adaptivity/stop_tolerance", "must lie in [0, 1)");
  }
  json job = small_job();
  job["adaptivity"] = {{"stop_tolerance", 0}};
  const ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->adaptivity.stop_tolerance, 0.0);
  EXPECT_EQ(r.problem->normalized["adaptivity"]["stop_tolerance"], 0.0);
}

TEST(JobErrors, AdaptivityMarkingIsGoalContactOrPlainAndGradingNonNegative) {
  json job = small_job();
  job["adaptivity"] = {{"marking", "dorfler"}};
  expect_only_error(parse(job), "/adaptivity/marking", "\"goal\"");
  job["adaptivity"] = {{"grading", -0.5}};
  expect_only_error(parse(job), "/adaptivity/grading", "must be >= 0");
  // The default: "goal" where the pressure estimate can be made (fem_bem, converge_then_refine, a domain
  // decomposition method) and no delta is given; "contact" otherwise, never an error.
  job["adaptivity"] = json::object();
  ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->adaptivity.marking, contact::MarkingRule::goal);
  EXPECT_EQ(r.problem->adaptivity.grading, 0.0);
  EXPECT_EQ(r.problem->normalized["adaptivity"]["marking"], "goal");
  for (const json& other : {json{{"delta", 0.05}}, json{{"indicator", "zz"}}}) {
    job["adaptivity"] = other;
    r = parse(job);
    ASSERT_TRUE(r.ok()) << listing(r);
    EXPECT_EQ(r.problem->adaptivity.marking, contact::MarkingRule::contact) << other.dump();
    EXPECT_EQ(r.problem->normalized["adaptivity"]["marking"], "contact") << other.dump();
  }
  job["adaptivity"] = json::object();
  job["solver"] = {{"method", "monolithic"}};
  r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->adaptivity.marking, contact::MarkingRule::contact);
  // Named where the estimate cannot be made: an error saying what it needs.
  job["adaptivity"] = {{"marking", "goal"}};
  expect_only_error(parse(job), "/adaptivity/marking", "a domain-decomposition method");
  job.erase("solver");
  job["adaptivity"] = {{"marking", "goal"}, {"indicator", "zz"}};
  expect_only_error(parse(job), "/adaptivity/marking", "the fem_bem indicator");
  job["adaptivity"] = {{"marking", "plain"}, {"grading", 0.25}};
  r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->adaptivity.marking, contact::MarkingRule::plain);
  EXPECT_EQ(r.problem->adaptivity.grading, 0.25);
}

TEST(JobDefaults, AdaptivityDefaultsToAllBodiesAndTheFemBemIndicator) {
  json job = small_job();
  job["adaptivity"] = json::object();
  const ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_TRUE(r.problem->adaptivity.enabled);
  EXPECT_TRUE(r.problem->adaptivity.bodies.empty());  // empty = all
  EXPECT_EQ(r.problem->adaptivity.indicator, contact::Indicator::fem_bem);
  EXPECT_EQ(r.problem->normalized["adaptivity"]["bodies"].size(), 2u);
  EXPECT_EQ(r.problem->normalized["adaptivity"]["delta"], 0.1);
  const ParseResult again = parse(r.problem->normalized);
  ASSERT_TRUE(again.ok()) << listing(again);
  EXPECT_EQ(again.problem->adaptivity.bodies.size(), 2u);
}

TEST(JobErrors, LoadAlongAPrescribedDisplacementComponentIsRejected) {
  // u_x = 0 on the left edge with a traction: its y component is a load, its x component would go into the support.
  json job = small_job();
  job["bodies"][0]["boundary"][0]["traction"] = {0, -1};
  EXPECT_TRUE(parse(job).ok()) << listing(parse(job));
  job["bodies"][0]["boundary"][0]["traction"] = {1, -1};
  expect_only_error(parse(job), "/bodies/0/boundary/0", "the load's x component acts where the x displacement");
  job["bodies"][0]["boundary"][0]["traction"] = {{"normal", 1.0}};
  expect_only_error(parse(job), "/bodies/0/boundary/0", "a normal pressure cannot be combined with a displacement");
}

TEST(JobErrors, FloatingBodyWithTheNeumannSchemeNamesTheBodyItsFreeMotionAndTheMethodsThatTakeIt) {
  json job = small_job();
  job["bodies"][1]["boundary"].erase(1);  // only {"x": 0} on the left remains: the flat contact holds y
  job["solver"] = {{"method", "neumann"}};
  expect_only_error(parse(job), "/solver/method", "body 'lower' floats (translation in y is free");
  EXPECT_NE(listing(parse(job)).find("\"interface_newton\""), std::string::npos) << listing(parse(job));
  // With the default method a floating body in contact is a valid job (whether its contacts hold it is decided by
  // the solve).
  job.erase("solver");
  EXPECT_TRUE(parse(job).ok()) << listing(parse(job));
}

TEST(JobErrors, AFloatingBodyThatSlidesAlongItsFlatFrictionlessContactIsRefusedAtValidation) {
  // Only {"y": 0} on the bottom: x is free, and a flat contact pushes along y only, whatever the loads.
  json job = small_job();
  job["bodies"][1]["boundary"].erase(0);
  expect_only_error(parse(job), "/bodies/1/boundary",
                    "body 'lower' floats (translation in x is free) and its frictionless contacts "
                    "'upper.bottom-lower.top' cannot hold it");
  EXPECT_NE(listing(parse(job)).find("translation in x (it slides along them)"), std::string::npos)
      << listing(parse(job));
}

TEST(JobErrors, TheNaiveRollerNamesThePlatesSlidingAndTheRollersSpinNotTheLoads) {
  // A roller between two plates, a force on the top plate and nothing else: the top plate can slide along its
  // flat contact, and the roller spin about its centre (0, 1), where all its contact normals meet.
  const json job = json::parse(R"({
    "name": "roller_naive",
    "bodies": [
      {"name": "base", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[-2, -1], [2, -1], [2, 0], [-2, 0]], "nx": 16, "ny": 4}},
       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]},
      {"name": "roller", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[-0.5, 0.1339745962155614], [0.5, 0.1339745962155614],
                                      [0.5, 1.8660254037844386], [-0.5, 1.8660254037844386]], "nx": 8, "ny": 8,
                          "edges": {"bottom": {"arc": {"center": [0, 1], "radius": 1}},
                                    "top": {"arc": {"center": [0, 1], "radius": 1}}}}}},
      {"name": "plate", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[-2, 2], [2, 2], [2, 3], [-2, 3]], "nx": 16, "ny": 4}},
       "boundary": [{"edge": "top", "force": [0, -100]}]}
    ],
    "contacts": [{"slave": "roller.bottom", "master": "base.top"}, {"slave": "roller.top", "master": "plate.bottom"}]
  })");
  const ParseResult r = parse(job);
  ASSERT_EQ(r.errors.size(), 2u) << listing(r);
  EXPECT_EQ(r.errors[0].pointer, "/bodies/1/boundary");
  EXPECT_NE(r.errors[0].message.find("body 'roller'"), std::string::npos) << listing(r);
  EXPECT_NE(r.errors[0].message.find("rotation about (0, 1) (it spins"), std::string::npos) << listing(r);
  EXPECT_EQ(r.errors[1].pointer, "/bodies/2/boundary");
  EXPECT_NE(r.errors[1].message.find("body 'plate'"), std::string::npos) << listing(r);
  EXPECT_NE(r.errors[1].message.find("translation in x (it slides along them)"), std::string::npos) << listing(r);
  for (const auto& e : r.errors) {
    EXPECT_EQ(e.message.find("pull"), std::string::npos) << e.message;
    EXPECT_EQ(e.message.find("loads move it"), std::string::npos) << e.message;
  }
}

TEST(JobBoundary, VertexConditionsForcesAndLoadingAreReadAndBadOnesNamed) {
  json job = small_job();
  job["bodies"][0]["boundary"].push_back({{"vertex", "bottom_right"}, {"force", {0, -5}}});
  job["bodies"][0]["boundary"].push_back({{"edge", "right"}, {"force", {1, 0}}});
  job["loading"] = {{"steps", 4}};
  ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  const auto& bc = r.problem->bodies[0].boundary;
  ASSERT_EQ(bc.size(), 4u);
  EXPECT_EQ(bc[2].vertex, "bottom_right");
  EXPECT_EQ(bc[2].kind, contact::BoundaryCondition::Kind::force);
  EXPECT_EQ(bc[2].force, Eigen::Vector2d(0, -5));
  EXPECT_EQ(bc[3].edge, "right");
  EXPECT_EQ(r.problem->loading.factors, (std::vector<double>{0.25, 0.5, 0.75, 1.0}));
  // Unknown vertex, a traction at a vertex, both edge and vertex, a load at a vertex a displacement holds.
  json bad = small_job();
  bad["bodies"][0]["boundary"] = {{{"vertex", "middle"}, {"displacement", {{"x", 0}}}},
                                  {{"vertex", "top_left"}, {"traction", {0, 1}}},
                                  {{"vertex", "top_right"}, {"edge", "top"}, {"force", {0, 1}}},
                                  {{"vertex", "bottom_left"}, {"displacement", {{"x", 0}}}},
                                  {{"vertex", "bottom_left"}, {"force", {0, 2}}}};
  r = parse(bad);
  const std::string text = listing(r);
  EXPECT_NE(text.find("/bodies/0/boundary/0/vertex: the body has no vertex 'middle'; its vertices are"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("/bodies/0/boundary/1: a vertex takes a displacement"), std::string::npos) << text;
  EXPECT_NE(text.find("/bodies/0/boundary/2: give exactly one of edge"), std::string::npos) << text;
  EXPECT_NE(
      text.find("/bodies/0/boundary/4/vertex: vertex 'bottom_left' already has a condition at /bodies/0/boundary/3"),
      std::string::npos)
      << text;
  // Loading: both forms, none, a non-positive factor, too many steps, and load steps with adaptivity.
  for (const auto& [loading, words] :
       std::vector<std::pair<json, std::string>>{{{{"steps", 2}, {"factors", {1}}}, "give either steps"},
                                                 {json::object(), "give either steps"},
                                                 {{{"factors", {0.5, -1}}}, "/loading/factors/1"},
                                                 {{{"steps", 5000}}, "steps = 5000 is too large"}}) {
    json j = small_job();
    j["loading"] = loading;
    EXPECT_NE(listing(parse(j)).find(words), std::string::npos) << loading.dump() << ": " << listing(parse(j));
  }
  // Load steps with adaptivity: converge_then_refine solves the path on each mesh; the paper's strategy cannot.
  json adaptive = small_job();
  adaptive["loading"] = {{"steps", 2}};
  adaptive["adaptivity"] = json::object();
  EXPECT_TRUE(parse(adaptive).ok()) << listing(parse(adaptive));
  adaptive["adaptivity"] = {{"strategy", "paper"}};
  EXPECT_NE(listing(parse(adaptive)).find("load steps with the adaptive strategy \"paper\" are not supported"),
            std::string::npos)
      << listing(parse(adaptive));
}

TEST(JobBoundary, ExplicitMeshVerticesTakePointLoadsAndBadOnesAreNamed) {
  json job = small_job();
  json mesh = explicit_mesh();
  for (auto& node : mesh["nodes"]) node[1] = node[1].get<double>() - 1.0;  // below the upper block
  mesh["edges"] = {{"base", {{0, 1}, {1, 2}}}, {"cap", {{5, 4}, {4, 3}}}, {"wall", {{3, 0}}}};
  mesh["vertices"] = {{"corner", 0}, {"tip", 5}};
  job["bodies"][1]["mesh"] = mesh;
  job["bodies"][1]["boundary"] = {{{"edge", "base"}, {"displacement", {{"y", 0}}}},
                                  {{"vertex", "corner"}, {"displacement", {{"x", 0}}}},
                                  {{"vertex", "tip"}, {"force", {3, 0}}}};
  job["contacts"][0]["master"] = "lower.cap";
  ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->bodies[1].mesh.vertices.at("corner"), 0);
  EXPECT_EQ(r.problem->bodies[1].mesh.vertices.at("tip"), 5);
  EXPECT_EQ(r.problem->normalized["bodies"][1]["mesh"]["vertices"], mesh["vertices"]);
  json bad = job;
  bad["bodies"][1]["mesh"]["vertices"] = {{"corner", 9}, {"b.d", 1}};
  bad["bodies"][1]["boundary"].erase(2);
  const std::string text = listing(parse(bad));
  EXPECT_NE(text.find("/bodies/1/mesh/vertices/corner: vertex 'corner' node index = 9 is out of range"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("/bodies/1/mesh/vertices/b.d"), std::string::npos) << text;
  bad = job;
  bad["bodies"][1]["boundary"][2]["vertex"] = "nose";
  expect_only_error(parse(bad), "/bodies/1/boundary/2/vertex", "the body has no vertex 'nose'; its vertices are");
}

TEST(JobErrors, NodeIndexOutOfRangeIsReportedAtTheIndex) {
  json job = small_job();
  job["bodies"][0]["mesh"] = explicit_mesh();
  job["bodies"][0]["mesh"]["quads"][0][2] = 6;
  job["contacts"][0]["slave"] = "upper.base";
  const ParseResult r = parse(job);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].pointer, "/bodies/0/mesh/quads/0/2") << listing(r);
  EXPECT_NE(r.errors[0].message.find("node index = 6 is out of range: the mesh has 6 nodes"), std::string::npos)
      << listing(r);
}

TEST(JobErrors, QuadRepeatingANodeIsRejected) {
  json job = small_job();
  job["bodies"][0]["mesh"] = explicit_mesh();
  job["bodies"][0]["mesh"]["quads"][0] = {0, 1, 1, 3};
  job["contacts"][0]["slave"] = "upper.base";
  const ParseResult r = parse(job);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].pointer, "/bodies/0/mesh/quads/0") << listing(r);
  EXPECT_NE(r.errors[0].message.find("repeats a node"), std::string::npos) << listing(r);
}

TEST(JobErrors, TooManyDegreesOfFreedomAreRefusedBeforeAnyMeshIsBuilt) {
  json job = small_job();
  job["bodies"][0]["mesh"]["block"]["nx"] = 1000000000;  // would need tens of gigabytes if generated
  expect_only_error(parse(job), "/bodies", "more than the limit of 2000000");

  // The limit is the caller's: the small job has 2 * (6 + 6) = 24 DOFs.
  Limits tight;
  tight.max_dofs = 20;
  expect_only_error(
      parse(small_job(), tight), "/bodies",
      "the meshes would have 24 degrees of freedom ('upper' 12 and 'lower' 12), more than the limit of 20");
}

TEST(JobErrors, NumberThatOverflowsIsNotFinite) {
  std::string text = small_job().dump();
  const std::string from = "210000.0";
  text.replace(text.find(from), from.size(), "1e400");
  expect_only_error(parse_text(text), "/bodies/0/material/E", "E must be a finite number (1e400 overflows a double)");

  const std::string in_array = R"({"bodies": [{"body_force": [0, -1e999]}]})";
  expect_only_error(parse_text(in_array), "/bodies/0/body_force/1", "must be a finite number");

  // A document built in memory can hold infinity itself.
  json job = small_job();
  job["bodies"][1]["material"]["E"] = std::numeric_limits<double>::infinity();
  expect_only_error(parse(job), "/bodies/1/material/E", "E must be a finite number");
}

TEST(JobErrors, MalformedJsonNamesTheByteOffset) {
  expect_only_error(parse_text(R"({"name": })"), "", "malformed JSON at byte 10");
}

TEST(JobErrors, NestingTooDeepIsRefusedBeforeParsing) {
  // Deep enough to overflow the stack of a recursive reader: it must be refused by counting brackets alone.
  const std::string text = std::string(200000, '[') + std::string(200000, ']');
  expect_only_error(parse_text(text), "", "nested deeper than 64 levels (at byte 65)");

  json deep = json::array();
  for (int k = 0; k < 100; ++k) deep = json::array({std::move(deep)});
  json job = small_job();
  job["extra"] = std::move(deep);
  expect_only_error(parse(job), "", "nested deeper than 64 levels");
}

TEST(JobErrors, BracketsInsideStringsDoNotCountAsNesting) {
  json job = small_job();
  job["name"] = std::string(100, '[') + "\\\"" + std::string(100, '{');  // also an escaped quote
  const ParseResult r = parse_text(job.dump());
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->name, job["name"].get<std::string>());
}

TEST(JobErrors, DuplicateKeyInTheTextIsReportedAtItsPointer) {
  const std::string text = R"({"bodies": [{"name": "a", "name": "b"}]})";
  const ParseResult r = parse_text(text);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].pointer, "/bodies/0/name") << listing(r);
  EXPECT_NE(r.errors[0].message.find("duplicate key 'name'"), std::string::npos) << listing(r);
}

TEST(JobErrors, DuplicateBodyNamesAreRejected) {
  json job = small_job();
  job["bodies"][1]["name"] = "upper";
  const ParseResult r = parse(job);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].pointer, "/bodies/1/name") << listing(r);
  EXPECT_NE(r.errors[0].message.find("body name 'upper' is already used by /bodies/0"), std::string::npos)
      << listing(r);
}

TEST(JobErrors, BodyNameWithADotIsRejectedSinceContactsReferToBodyDotEdge) {
  json job = small_job();
  job["bodies"][0]["name"] = "up.per";
  const ParseResult r = parse(job);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].pointer, "/bodies/0/name") << listing(r);
  EXPECT_NE(r.errors[0].message.find("^[A-Za-z0-9_-]+$"), std::string::npos) << listing(r);
}

TEST(JobErrors, SeveralErrorsAreAllReportedInOneAnswer) {
  json job = small_job();
  job["bodies"][0]["material"]["nu"] = 0.5;
  job["bodies"][1]["mesh"]["block"]["ny"] = 0;
  job["contacts"][0]["master"] = "lower.tip";
  job["solver"] = {{"gamma", 3}, {"tolerance", -1}};
  job["colour"] = "red";
  const ParseResult r = parse(job);
  ASSERT_EQ(r.errors.size(), 6u) << listing(r);
  std::vector<std::string> pointers;
  for (const auto& e : r.errors) pointers.push_back(e.pointer);
  std::sort(pointers.begin(), pointers.end());
  EXPECT_EQ(pointers, (std::vector<std::string>{"/bodies/0/material/nu", "/bodies/1/mesh/block/ny", "/colour",
                                                "/contacts/0/master", "/solver/gamma", "/solver/tolerance"}));
}

TEST(BadJobs, HugeButFiniteNumberIsRejectedAtItsPointer) {
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/examples/flat_patch.json");
  nlohmann::json job = nlohmann::json::parse(in);
  job["bodies"][0]["material"]["E"] = 1e308;
  const auto r = contact::job::parse(job);
  ASSERT_EQ(r.errors.size(), 1u) << contact::job::format_errors(r.errors);
  EXPECT_EQ(r.errors[0].pointer, "/bodies/0/material/E");
  EXPECT_NE(r.errors[0].message.find("too large"), std::string::npos);
}

// ---- limits on every field that sets the work or the resources of a job (docs/job-format.md, "Limits") -----

TEST(JobLimits, AThirtyThousandCharacterNameIsAnErrorNotAStackOverflow) {
  // std::regex_match recursed once per character: names of ~30 000 characters crashed the parser.
  const std::string long_name(30000, 'a');
  for (const char* where : {"body", "edge", "contact"}) {
    json job = small_job();
    std::string pointer;
    if (std::string(where) == "body") {
      job["bodies"][0]["name"] = long_name;
      pointer = "/bodies/0/name";
    } else if (std::string(where) == "edge") {
      job["bodies"][0]["mesh"] = explicit_mesh();
      job["bodies"][0]["mesh"]["edges"][long_name] = {{0, 1}};
      pointer = "/bodies/0/mesh/edges/" + long_name.substr(0, 1000);
    } else {
      job["contacts"][0]["name"] = long_name + "!";
      pointer = "/contacts/0/name";
    }
    const ParseResult r = parse_text(job.dump());
    ASSERT_FALSE(r.ok()) << where;
    bool found = false;
    for (const auto& e : r.errors)
      if (e.pointer.rfind(pointer, 0) == 0 && e.message.find("too long: at most") != std::string::npos) {
        found = true;
        EXPECT_LT(e.message.size(), 200u) << "the message must not echo the whole name";
      }
    EXPECT_TRUE(found) << where << ":\n" << listing(r).substr(0, 2000);
  }
  // A name of a million invalid characters is answered quickly too (no recursion, no quadratic work).
  json job = small_job();
  job["bodies"][1]["name"] = std::string(1000000, '*');
  const ParseResult r = parse(job);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].pointer, "/bodies/1/name") << listing(r).substr(0, 2000);
}

TEST(JobLimits, NamesAtTheLimitAreAcceptedAndCharactersAreStillChecked) {
  json job = small_job();
  const std::string name(64, 'u');  // the documented limit
  job["bodies"][0]["name"] = name;
  job["contacts"][0]["slave"] = name + ".bottom";
  const ParseResult ok = parse(job);
  EXPECT_TRUE(ok.ok()) << listing(ok);
  job = small_job();
  job["bodies"][0]["name"] = "up per";
  job["contacts"] = json::array();
  expect_only_error(parse(job), "/bodies/0/name", "must consist of letters, digits, '_' and '-' only");
  job = small_job();
  job["contacts"][0]["name"] = "upper.bottom-lower.top";  // '.' is allowed in contact names
  EXPECT_TRUE(parse(job).ok());
  job["contacts"][0]["name"] = "a/b";
  expect_only_error(parse(job), "/contacts/0/name", "'_', '-' and '.' only");
  job = small_job();
  job["name"] = std::string(300, 'j');
  expect_only_error(parse(job), "/name", "too long: at most 256 characters");
}

TEST(JobLimits, ThreadsAboveTheBoundAreRejected) {
  // solver.threads = 1000000 exhausted the host's process ids and hung the worker.
  json job = small_job();
  job["solver"] = {{"threads", 1000000}};
  expect_only_error(parse(job), "/solver/threads", "threads = 1000000 is too large (at most 64)");
  job["solver"] = {{"threads", 64}};
  EXPECT_TRUE(parse(job).ok());
}

TEST(JobLimits, IterationAndUpdateCountsHaveUpperBounds) {
  json job = small_job();
  job["solver"] = {{"max_iterations", 100001}};
  expect_only_error(parse(job), "/solver/max_iterations", "at most 100000");
  job["solver"] = {{"max_iterations", 100000}};
  EXPECT_TRUE(parse(job).ok());
  job["solver"] = {{"augmented_lagrangian", {{"max_updates", 1000000}}}};
  expect_only_error(parse(job), "/solver/augmented_lagrangian/max_updates", "at most 1000");
  job = small_job();
  job["adaptivity"] = {{"max_steps", 101}};
  expect_only_error(parse(job), "/adaptivity/max_steps", "at most 100");
  job["adaptivity"] = {{"max_dofs", 2000001}};
  expect_only_error(parse(job), "/adaptivity/max_dofs", "at most 2000000");
}

TEST(JobLimits, TooManyBodiesOrContactsAreRefusedBeforeAnyIsRead) {
  json job = small_job();
  json bodies = json::array();
  for (int k = 0; k < 20000; ++k) bodies.push_back({{"name", "b" + std::to_string(k)}});  // each one invalid
  job["bodies"] = bodies;
  job["contacts"] = json::array();
  const ParseResult r = parse(job);
  ASSERT_EQ(r.errors.size(), 1u) << listing(r).substr(0, 2000);
  EXPECT_EQ(r.errors[0].pointer, "/bodies");
  EXPECT_NE(r.errors[0].message.find("20000 bodies; at most " + std::to_string(Limits{}.max_bodies)), std::string::npos)
      << listing(r);

  job = small_job();
  job["contacts"] = json::array();
  const int too_many = Limits{}.max_contacts + 1;
  for (int k = 0; k < too_many; ++k) job["contacts"].push_back({{"slave", "upper.bottom"}, {"master", "lower.top"}});
  expect_only_error(parse(job), "/contacts",
                    std::to_string(too_many) + " contact pairs; at most " + std::to_string(too_many - 1));
}

TEST(JobLimits, AnEdgeSideListedTwiceIsAnErrorNotADoubleLoad) {
  json job = small_job();
  job["bodies"][0]["mesh"] = explicit_mesh();
  job["bodies"][0]["mesh"]["edges"]["cap"] = {{5, 4}, {4, 3}, {4, 5}};  // [4, 5] is [5, 4] again
  job["bodies"][0]["boundary"] = {{{"edge", "wall"}, {"displacement", {{"x", 0}, {"y", 0}}}},
                                  {{"edge", "cap"}, {"traction", {0, -1}}}};
  job["contacts"][0]["slave"] = "upper.base";
  expect_only_error(parse(job), "/bodies/0/mesh/edges/cap/2",
                    "the side [4, 5] of edge 'cap' is already listed at /bodies/0/mesh/edges/cap/0");
}

TEST(JobLimits, ErrorListsAreBoundedWhateverTheDocument) {
  // 5000 unknown fields with long names: at most Errors::kMaxErrors entries, each message and pointer cut.
  json job = small_job();
  for (int k = 0; k < 5000; ++k) job["x" + std::to_string(k) + std::string(5000, 'k')] = k;
  const ParseResult r = parse(job);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors.size(), 201u);
  EXPECT_NE(r.errors.back().message.find("and 4800 more errors"), std::string::npos) << r.errors.back().message;
  for (const auto& e : r.errors) {
    EXPECT_LE(e.pointer.size(), 1030u);
    EXPECT_LE(e.message.size(), 1030u);
  }
}

// Issue 22, defect 7: a job name with a NUL was accepted, and the result file's name attribute was cut at it.
// Control characters in any name are refused at their pointer, and messages show them escaped.
TEST(JobErrors, ControlCharactersInNamesAreRefusedAtTheirPointer) {
  json job = small_job();
  job["name"] = std::string("seed\0layers", 11);
  expect_only_error(parse(job), "/name", "name 'seed\\u0000layers' contains the control character U+0000 at byte 4");
  job["name"] = "red \x1b[31m";
  expect_only_error(parse(job), "/name", "contains the control character U+001B at byte 4");
  job["name"] = "tab\there";
  expect_only_error(parse(job), "/name", "U+0009");
  job["name"] = "c1 \xc2\x9b";  // U+009B, the one-byte CSI of C1
  expect_only_error(parse(job), "/name", "U+009B");
  job["name"] = "Grenzfläche 2 (ü)";  // printable non-ASCII stays allowed
  EXPECT_TRUE(parse(job).ok()) << listing(parse(job));
  // Names that the job refers to are identifiers, which cannot hold control characters either.
  job = small_job();
  job["bodies"][0]["name"] = std::string("up\0per", 6);
  job["contacts"] = json::array();
  expect_only_error(parse(job), "/bodies/0/name", "body name 'up\\u0000per' must consist of letters, digits");
  job = small_job();
  job["contacts"][0]["name"] = "pair\x07";
  expect_only_error(parse(job), "/contacts/0/name", "contact name 'pair\\u0007' must consist of letters");
  job = small_job();
  job["bodies"][0]["boundary"][1]["edge"] = "top\x1b";
  expect_only_error(parse(job), "/bodies/0/boundary/1/edge", "the body has no edge 'top\\u001B'");
}

// Issue 32, item 7: a contact named "." validated, and the finished job then failed writing its result (the
// result lost); ".." became an HDF5 group "..". Zero-width and bidirectional-control characters (U+200B-U+200F,
// U+202A-U+202E, U+2066-U+2069, U+FEFF) let a name read as another. Both are refused in every name, at its
// pointer, the character named by its code point and shown escaped.
TEST(JobErrors, DotNamesAreRefusedAtTheirPointer) {
  for (const char* dots : {".", ".."}) {
    json job = small_job();
    job["contacts"][0]["name"] = dots;
    expect_only_error(parse(job), "/contacts/0/name",
                      "contact name '" + std::string(dots) + "' is not a name: '.' and '..' mean");
    job = small_job();
    job["bodies"][0]["name"] = dots;
    job["contacts"] = json::array();
    expect_only_error(parse(job), "/bodies/0/name", "body name '" + std::string(dots) + "' must consist of letters");
    // An explicit mesh's edge and vertex names.
    job = small_job();
    job["bodies"][0]["mesh"] = explicit_mesh();
    job["bodies"][0]["mesh"]["edges"][dots] = job["bodies"][0]["mesh"]["edges"]["side"];
    job["bodies"][0]["mesh"]["edges"].erase("side");
    job["bodies"][0]["boundary"] = {{{"edge", "wall"}, {"displacement", {{"x", 0}, {"y", 0}}}}};
    job["contacts"][0]["slave"] = "upper.base";
    expect_only_error(parse(job), "/bodies/0/mesh/edges/" + std::string(dots),
                      "edge name '" + std::string(dots) + "' must consist of letters");
    job["bodies"][0]["mesh"] = explicit_mesh();
    job["bodies"][0]["mesh"]["vertices"] = {{dots, 0}};
    expect_only_error(parse(job), "/bodies/0/mesh/vertices/" + std::string(dots),
                      "vertex name '" + std::string(dots) + "' must consist of letters");
  }
  // Dots inside a contact name stay allowed (the default names have them).
  json job = small_job();
  for (const char* fine : {"upper.bottom-lower.top", "a.b", "...", ".x"}) {
    job["contacts"][0]["name"] = fine;
    EXPECT_TRUE(parse(job).ok()) << fine << ": " << listing(parse(job));
  }
}

TEST(JobErrors, InvisibleCharactersInNamesAreRefusedAndNamedByCodePoint) {
  const std::string rlo = "\xe2\x80\xae";   // U+202E RIGHT-TO-LEFT OVERRIDE
  const std::string zwsp = "\xe2\x80\x8b";  // U+200B ZERO WIDTH SPACE
  const std::string lri = "\xe2\x81\xa6";   // U+2066 LEFT-TO-RIGHT ISOLATE
  const std::string bom = "\xef\xbb\xbf";   // U+FEFF ZERO WIDTH NO-BREAK SPACE
  json job = small_job();
  job["name"] = "report" + rlo + "fdp.exe";
  expect_only_error(parse(job), "/name",
                    "name 'report\\u202Efdp.exe' contains the invisible character U+202E at byte 6: it must be "
                    "printable text");
  job["name"] = "seed" + zwsp;
  expect_only_error(parse(job), "/name", "U+200B at byte 4");
  job["name"] = bom + "seed";
  expect_only_error(parse(job), "/name", "U+FEFF at byte 0");
  job["name"] = "seed\xe2\x80\xaf";  // U+202F NARROW NO-BREAK SPACE: visible spacing, allowed
  EXPECT_TRUE(parse(job).ok()) << listing(parse(job));

  job = small_job();
  job["bodies"][1]["name"] = "low" + rlo + "er";
  job["contacts"] = json::array();
  expect_only_error(parse(job), "/bodies/1/name",
                    "body name 'low\\u202Eer' must consist of letters, digits, '_' and '-' only (pattern "
                    "^[A-Za-z0-9_-]+$); it contains the invisible character U+202E at byte 3");
  job = small_job();
  job["contacts"][0]["name"] = "pair" + zwsp;
  expect_only_error(parse(job), "/contacts/0/name", "contains the invisible character U+200B at byte 4");
  job = small_job();
  job["bodies"][0]["mesh"] = explicit_mesh();
  job["bodies"][0]["mesh"]["vertices"] = {{"tip" + lri, 0}};
  job["bodies"][0]["boundary"] = {{{"edge", "wall"}, {"displacement", {{"x", 0}, {"y", 0}}}}};
  job["contacts"][0]["slave"] = "upper.base";
  expect_only_error(parse(job), "/bodies/0/mesh/vertices/tip" + lri, "contains the invisible character U+2066");
  job["bodies"][0]["mesh"] = explicit_mesh();
  job["bodies"][0]["mesh"]["edges"]["cap" + bom] = job["bodies"][0]["mesh"]["edges"]["cap"];
  job["bodies"][0]["mesh"]["edges"].erase("cap");
  expect_only_error(parse(job), "/bodies/0/mesh/edges/cap" + bom, "contains the invisible character U+FEFF");
}

// Issue 31, item 4: past a limit a job got its one real error followed by hundreds that only repeated it
// ("/contacts/0/slave: there is no body named 'b0_0'; the bodies are (none)"). docs/job-format.md: problems that
// depend on earlier ones are not reported on top of them. One cause, one error, past every limit.
namespace {
// `bodies` blocks in a row, each held at its bottom, and a contact between each and the next.
json row_of_blocks(int bodies) {
  json job = {{"name", "row"}, {"bodies", json::array()}, {"contacts", json::array()}};
  for (int k = 0; k < bodies; ++k) {
    const double y = k;
    job["bodies"].push_back(
        {{"name", "b" + std::to_string(k)},
         {"material", {{"E", 1}, {"nu", 0.3}}},
         {"mesh", {{"block", {{"corners", {{0, y}, {1, y}, {1, y + 1}, {0, y + 1}}}, {"nx", 1}, {"ny", 1}}}}},
         {"boundary", {{{"edge", "bottom"}, {"displacement", {{"x", 0}, {"y", 0}}}}}}});
    if (k > 0)
      job["contacts"].push_back(
          {{"slave", "b" + std::to_string(k) + ".bottom"}, {"master", "b" + std::to_string(k - 1) + ".top"}});
  }
  return job;
}
}  // namespace

TEST(JobLimits, TooManyBodiesIsOneErrorNotOnePerContactThatNamesThem) {
  Limits limits;
  limits.max_bodies = 512;
  json job = row_of_blocks(589);
  job["adaptivity"] = {{"indicator", "zz"}, {"bodies", {"b0", "b1"}}};
  expect_only_error(parse(job, limits), "/bodies", "the job has 589 bodies; at most 512 are accepted");
  // Bodies that are not a list at all, or missing: the same.
  job["bodies"] = {{"b0", 1}};
  expect_only_error(parse(job, limits), "/bodies", "bodies must be an array");
  job.erase("bodies");
  expect_only_error(parse(job, limits), "/bodies", "required field 'bodies' is missing");
}

TEST(JobLimits, ABodyWhoseNameIsInErrorIsNotReportedAgainByTheContactsThatNameIt) {
  json job = small_job();
  job["bodies"][0]["name"] = "up per";
  expect_only_error(parse(job), "/bodies/0/name", "body name 'up per' must consist of letters");
  // Every body named, the name misspelt: that is the contact's own error.
  job = small_job();
  job["contacts"][0]["slave"] = "uper.bottom";
  expect_only_error(parse(job), "/contacts/0/slave", "there is no body named 'uper'; the bodies are upper and lower");
}

TEST(JobLimits, TooManyContactsIsOneErrorNotOnePerBodyTheyWouldHold) {
  // Each block held only sideways: its contacts hold it up. Refused contacts say nothing of whether they would.
  Limits limits;
  limits.max_contacts = 20;
  json job = row_of_blocks(30);
  for (size_t k = 1; k < job["bodies"].size(); ++k)
    job["bodies"][k]["boundary"] = {{{"edge", "left"}, {"displacement", {{"x", 0}}}}};
  ASSERT_TRUE(parse(job).ok()) << listing(parse(job));
  expect_only_error(parse(job, limits), "/contacts", "the job has 29 contact pairs; at most 20 are accepted");
  job["contacts"] = "all of them";
  expect_only_error(parse(job, limits), "/contacts", "contacts must be an array");
  // One pair in error (a misspelt body, a bad gap): the top block, which only that pair holds up, is not reported
  // as floating on top of it.
  job["contacts"] = row_of_blocks(30)["contacts"];
  job["contacts"][28]["master"] = "b2B.top";
  expect_only_error(parse(job), "/contacts/28/master", "there is no body named 'b2B'");
  job["contacts"][28]["master"] = "b28.top";
  job["contacts"][28]["gap"] = {{"constant", "wide"}};
  expect_only_error(parse(job), "/contacts/28/gap/constant", "constant must be a number");
}

TEST(JobLimits, TooManyLoadStepsIsOneErrorNotOnePerHistory) {
  json job = small_job();
  job["bodies"][0]["boundary"][1]["history"] = {1, 2, 3};
  job["bodies"][1]["boundary"][1]["history"] = {1, 1, 1};
  job["loading"] = {{"steps", 3}};
  ASSERT_TRUE(parse(job).ok()) << listing(parse(job));
  job["loading"] = {{"steps", Limits{}.max_load_steps + 1}};
  expect_only_error(parse(job), "/loading/steps", "is too large (at most 1000)");
  json factors = json::array();
  for (int k = 0; k <= Limits{}.max_load_steps; ++k) factors.push_back(1);
  job["loading"] = {{"factors", factors}};
  expect_only_error(parse(job), "/loading/factors", "at most 1000 load steps");
  job["loading"] = {{"factors", {1, -1, 2}}};
  expect_only_error(parse(job), "/loading/factors/1", "must be positive");
  job["loading"] = {{"steps", 3}, {"factors", {1, 2, 3}}};
  expect_only_error(parse(job), "/loading", "give either steps");
  job["loading"] = {{"steps", 2}};  // a number of steps that is known and wrong: the histories' own error
  ASSERT_EQ(parse(job).errors.size(), 2u) << listing(parse(job));
}

TEST(JobLimits, TooManyDegreesOfFreedomIsOneErrorWhateverTheContactsAndConditions) {
  json job = small_job();
  job["bodies"][0]["mesh"]["block"]["nx"] = 100000;
  job["bodies"][0]["mesh"]["block"]["ny"] = 100000;
  job["bodies"][0]["boundary"] = {{{"edge", "top"}, {"displacement", {{"y", -0.001}}}}};  // floats in x
  expect_only_error(parse(job), "/bodies", "more than the limit of 2000000");
}

// "output": which steps' fields the result keeps (issue 23, item 3). The default follows the job: the last step
// of an adaptive run, every load step otherwise; the normalized copy says which.
TEST(JobOutput, StepsDefaultToLastForAdaptiveJobsAndAllOtherwiseAndBadValuesAreNamed) {
  json job = small_job();
  ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->output.steps, contact::StepOutput::all);
  EXPECT_EQ(r.problem->normalized["output"], json({{"steps", "all"}, {"iterate", false}}));
  job["adaptivity"] = json::object();
  r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->output.steps, contact::StepOutput::last);
  EXPECT_EQ(r.problem->normalized["output"], json({{"steps", "last"}, {"iterate", false}}));
  job["output"] = {{"steps", "all"}};
  r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->output.steps, contact::StepOutput::all);
  json steps = small_job();
  steps["loading"] = {{"steps", 3}};
  steps["output"] = {{"steps", "last"}};
  r = parse(steps);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->output.steps, contact::StepOutput::last);
  steps["output"] = {{"steps", "first"}};
  expect_only_error(parse(steps), "/output/steps", "steps \"first\" is not one of \"last\" and \"all\"");
  steps["output"] = {{"fields", "all"}};
  expect_only_error(parse(steps), "/output/fields", "fields");
  steps["output"] = "last";
  expect_only_error(parse(steps), "/output", "object");
  // iterate: whether an unconverged step keeps its iterate; a boolean, false unless asked for.
  steps["output"] = {{"iterate", true}};
  r = parse(steps);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_TRUE(r.problem->output.iterate);
  EXPECT_EQ(r.problem->normalized["output"]["iterate"], true);
  steps["output"] = {{"iterate", "yes"}};
  expect_only_error(parse(steps), "/output/iterate", "iterate");
}

// ---- friction and load histories (docs/job-format.md, "Friction") ----------------------------------------

TEST(JobFriction, CoulombAndTrescaAreReadAndTheirErrorsNamed) {
  json job = small_job();
  job["contacts"][0]["friction"] = {{"coefficient", 0.3}};
  ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->contacts[0].friction.law, contact::FrictionSpec::Law::coulomb);
  EXPECT_EQ(r.problem->contacts[0].friction.coefficient, 0.3);
  job["contacts"][0]["friction"] = {{"bound", 2.5}};
  r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->contacts[0].friction.law, contact::FrictionSpec::Law::tresca);
  EXPECT_EQ(r.problem->contacts[0].friction.bound, 2.5);
  // Without it: frictionless.
  EXPECT_FALSE(parse(small_job()).problem->contacts[0].friction.active());

  job["contacts"][0]["friction"] = {{"coefficient", 0.3}, {"bound", 1}};
  expect_only_error(parse(job), "/contacts/0/friction", "exactly one of coefficient");
  job["contacts"][0]["friction"] = json::object();
  expect_only_error(parse(job), "/contacts/0/friction", "exactly one of coefficient");
  job["contacts"][0]["friction"] = {{"coefficient", -0.1}};
  expect_only_error(parse(job), "/contacts/0/friction/coefficient", "is negative");
  job["contacts"][0]["friction"] = {{"bound", "high"}};
  expect_only_error(parse(job), "/contacts/0/friction/bound", "must be a number");
  job["contacts"][0]["friction"] = {{"mu", 0.3}};
  expect_only_error(parse(job), "/contacts/0/friction/mu", "unknown field 'mu'");
}

TEST(JobFriction, MethodsEnforcementsAndAdaptivityThatCannotTakeItAreRefused) {
  json job = small_job();
  job["contacts"][0]["friction"] = {{"coefficient", 0.3}};
  job["solver"] = {{"method", "neumann"}};
  expect_only_error(parse(job), "/contacts/0/friction", "method \"neumann\" cannot take it");
  job["solver"] = {{"method", "robin"}};
  expect_only_error(parse(job), "/contacts/0/friction", "method \"robin\" cannot take it");
  job["solver"] = {{"method", "interface_newton"}, {"enforcement", "penalty"}};
  expect_only_error(parse(job), "/contacts/0/friction", "needs exact contact");
  job["solver"] = {{"interface", {{"solver", "iterative"}}}};  // FETI on the box of the friction multipliers
  EXPECT_TRUE(parse(job).ok());
  job["solver"] = {{"method", "monolithic"}};
  EXPECT_TRUE(parse(job).ok());
  job["solver"] = {{"interface", {{"solver", "direct"}}}};
  EXPECT_TRUE(parse(job).ok());
  job.erase("solver");
  job["adaptivity"] = {{"indicator", "zz"}};  // adapts: the indicators take the whole contact traction
  EXPECT_TRUE(parse(job).ok()) << listing(parse(job));
}

TEST(JobFriction, AFlatContactWithFrictionMayHoldASlidingBody) {
  // The upper block held only in y at its top: frictionless, nothing stops it sliding in x (refused at
  // validation); with friction the contact may hold it.
  json job = small_job();
  job["bodies"][0]["boundary"] = json::parse(R"([{"edge": "top", "displacement": {"y": -0.001}}])");
  expect_only_error(parse(job), "/bodies/0/boundary", "it slides along them");
  job["contacts"][0]["friction"] = {{"coefficient", 0.5}};
  EXPECT_TRUE(parse(job).ok()) << listing(parse(job));
}

TEST(JobHistory, AConditionsHistoryHasOneFactorPerLoadStep) {
  json job = small_job();
  job["bodies"][0]["boundary"][1]["history"] = {1, 0, 2};
  job["loading"] = {{"steps", 3}};
  ParseResult r = parse(job);
  ASSERT_TRUE(r.ok()) << listing(r);
  EXPECT_EQ(r.problem->bodies[0].boundary[1].history, (std::vector<double>{1, 0, 2}));
  job["loading"] = {{"steps", 2}};
  expect_only_error(parse(job), "/bodies/0/boundary/1/history",
                    "history has 3 load factors but the job has 2 load steps");
  job["bodies"][0]["boundary"][1]["history"] = json::array();
  expect_only_error(parse(job), "/bodies/0/boundary/1/history", "non-empty array");
  job["bodies"][0]["boundary"][1]["history"] = {1, "two"};
  expect_only_error(parse(job), "/bodies/0/boundary/1/history/1", "must be a number");
  job["bodies"][0]["boundary"][1]["history"] = {1};
  job.erase("loading");
  job["adaptivity"] = {{"indicator", "zz"}};  // converge_then_refine solves the (one-step) path on each mesh
  EXPECT_TRUE(parse(job).ok()) << listing(parse(job));
  job["adaptivity"] = {{"strategy", "paper"}};
  EXPECT_NE(listing(parse(job))
                .find("/bodies/0/boundary/1/history: a load history needs load steps, which the "
                      "adaptive strategy \"paper\" does not take"),
            std::string::npos)
      << listing(parse(job));
}

// Issue 51, item 1: two clamped one-element blocks side by side and the pair b0.top -> b1.bottom, whose edges
// never face each other, crashed the direct interface solver (an empty interface problem). The reader refuses
// such a pair, naming it and the edges' ends; the pair that does face is accepted, slave and master either way.
namespace {
json two_clamped_blocks(const std::string& slave, const std::string& master, double x1 = 1.5) {
  json job = json::parse(R"({"bodies": [
    {"name": "b0", "material": {"E": 1, "nu": 0.3},
     "mesh": {"block": {"corners": [[0, 0], [1, 0], [1, 1], [0, 1]], "nx": 1, "ny": 1}},
     "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]},
    {"name": "b1", "material": {"E": 1, "nu": 0.3},
     "mesh": {"block": {"corners": [[1.5, 0], [2.5, 0], [2.5, 1], [1.5, 1]], "nx": 1, "ny": 1}},
     "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]}]})");
  job["bodies"][1]["mesh"]["block"]["corners"] = {{x1, 0}, {x1 + 1, 0}, {x1 + 1, 1}, {x1, 1}};
  job["contacts"] = {{{"slave", slave}, {"master", master}}};
  return job;
}
}  // namespace

TEST(JobContacts, APairWhoseEdgesNeverFaceEachOtherIsRefusedWithItsEnds) {
  expect_only_error(parse(two_clamped_blocks("b0.top", "b1.bottom")), "/contacts/0",
                    "the edges of pair 'b0.top-b1.bottom' never face each other (slave b0.top runs from (1, 1) to "
                    "(0, 1), master b1.bottom from (1.5, 0) to (2.5, 0)): no side of the master lies opposite");
  // Opposite each other, but the bodies on the same side: b1.left's outward normal points at b0, b0.left's away.
  expect_only_error(parse(two_clamped_blocks("b1.left", "b0.left")), "/contacts/0",
                    "their outward normals point the same way");
  // The edges that meet, either body the slave; and across a gap (the gap may close).
  EXPECT_TRUE(parse(two_clamped_blocks("b1.left", "b0.right")).ok());
  EXPECT_TRUE(parse(two_clamped_blocks("b0.right", "b1.left")).ok());
  EXPECT_TRUE(parse(two_clamped_blocks("b0.right", "b1.left", 1.0)).ok());
  // Overlapping by half a side along the slave's normal is facing; touching at a corner point is not.
  json shifted = two_clamped_blocks("b1.bottom", "b0.top");
  shifted["bodies"][1]["mesh"]["block"]["corners"] = {{0.5, 1}, {1.5, 1}, {1.5, 2}, {0.5, 2}};
  EXPECT_TRUE(parse(shifted).ok()) << listing(parse(shifted));
  shifted["bodies"][1]["mesh"]["block"]["corners"] = {{1, 1}, {2, 1}, {2, 2}, {1, 2}};
  expect_only_error(parse(shifted), "/contacts/0", "never face each other");
}
