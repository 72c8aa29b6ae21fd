// Result file I/O: what write_result writes, read_result reads back bit for bit; the VTKHDF partition sizes
// agree; failures name the path and leave no file; the XDMF sidecar names every step and body.
#include "contact/job.hpp"
#include "contact/result_file.hpp"
#include "contact/solve.hpp"
#include "ddm/step_log.hpp"
#include "io/h5.hpp"
#include "triangle_meshes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <regex>
#include <sstream>
#include <thread>

using namespace contact;
namespace fs = std::filesystem;

namespace {

fs::path output_dir() {
  const fs::path dir = fs::path(CONTACT_BINARY_DIR) / "test_io_output";
  fs::create_directories(dir);
  return dir;
}

mesh::Mesh block(double x0, double y0, double x1, double y1, int nx, int ny) {
  mesh::BlockSpec s;
  s.corners = {mesh::Point(x0, y0), mesh::Point(x1, y0), mesh::Point(x1, y1), mesh::Point(x0, y1)};
  s.nx = nx;
  s.ny = ny;
  return mesh::make_block(s);
}

// Made-up but consistent fields: every value differs, so a transposed or shifted array would be caught.
BodyField body_field(const std::string& name, mesh::Mesh m, bool with_indicator) {
  BodyField b;
  b.name = name;
  const Eigen::Index n = m.num_nodes(), c = m.num_cells();
  b.displacement.resize(n, 2);
  b.stress_node.resize(n, 4);
  b.reaction = Eigen::MatrixX2d::Zero(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& p = m.nodes[static_cast<size_t>(i)];
    b.displacement.row(i) << 1e-3 * p.x() + 1e-6 * static_cast<double>(i), -2e-3 * p.y();
    b.stress_node.row(i) << p.x(), p.y(), 0.5 * p.x() * p.y(), -0.3 * (p.x() + p.y());
    if (p.y() == m.bbox_max().y()) b.reaction.row(i) << 0.0, -static_cast<double>(i + 1);
  }
  b.stress_cell.resize(c, 4);
  b.von_mises_cell.resize(c);
  for (Eigen::Index e = 0; e < c; ++e) {
    const double s = static_cast<double>(e);
    b.stress_cell.row(e) << -10.0 - s, -20.0 + s, 0.25 * s, -9.0;
    b.von_mises_cell(e) = 15.0 + 0.5 * s;
  }
  if (with_indicator) {
    b.indicator_cell.resize(c);
    for (Eigen::Index e = 0; e < c; ++e) b.indicator_cell(e) = 1.0 / static_cast<double>(e + 1);
  }
  b.mesh = std::move(m);
  return b;
}

PairField pair_field(const BodyField& slave, double theta) {
  PairField p;
  p.name = "upper.bottom~lower.top";
  p.slave_body = "upper";
  p.slave_edge = "bottom";
  p.master_body = "lower";
  p.master_edge = "top";
  p.theta = theta;
  const auto nodes = slave.mesh.edge_set_nodes("bottom");
  const auto n = static_cast<Eigen::Index>(nodes.size());
  p.enforcement = "penalty";
  p.node.resize(n);
  p.position.resize(n, 2);
  p.normal.resize(n, 2);
  p.arc_length.resize(n);
  p.weight.resize(n);
  p.gap.resize(n);
  p.normal_gap.resize(n);
  p.pressure.resize(n);
  p.penetration.resize(n);
  p.active.resize(n);
  p.status.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto& x = slave.mesh.nodes[static_cast<size_t>(nodes[static_cast<size_t>(k)])];
    p.node[k] = nodes[static_cast<size_t>(k)];
    p.position.row(k) = x.transpose();
    p.normal.row(k) << 0.0, -1.0;
    p.weight(k) = k == 0 || k == n - 1 ? 0.25 : 0.5;
    p.status(k) = k == 0 ? 2 : 0;
    p.arc_length(k) = x.x() - slave.mesh.nodes[static_cast<size_t>(nodes.front())].x();
    p.gap(k) = 1e-3 * x.x() * x.x();
    p.normal_gap(k) = p.gap(k) - 2e-3;
    p.penetration(k) = std::max(0.0, -p.normal_gap(k));
    p.pressure(k) = p.penetration(k) / theta;
    p.active(k) = p.penetration(k) > 0 ? 1 : 0;
  }
  p.force = p.pressure.sum() * 0.5;
  return p;
}

IterationReport report(int iteration, const Step& s) {
  IterationReport r;
  r.iteration = iteration;
  r.paper_criterion = 0.1 / iteration;
  r.fixed_point_residual = 0.05 / iteration;
  r.complementarity = 0.01 / iteration;
  r.active_nodes = 3 + iteration;
  r.active_set_changes = 2 - iteration;
  r.update = iteration - 1;
  r.elapsed_seconds = 0.25 * iteration;
  for (const auto& b : s.bodies)
    r.bodies.push_back({b.name, b.mesh.num_cells(), 2 * b.mesh.num_nodes() - 4, iteration == 2 ? 3 : 0});
  for (const auto& p : s.pairs) {
    PairReport pr;
    pr.name = p.name;
    pr.force = p.force * iteration;
    pr.max_pressure = p.pressure.size() > 0 ? p.pressure.maxCoeff() : 0.0;
    pr.extent_begin = 0.5;
    pr.extent_end = 1.5 + iteration;
    pr.active_nodes = p.active.sum();
    pr.changed_nodes = 2 - iteration;
    pr.theta = p.theta;
    pr.positions = {0.0, 1.0};
    pr.pressures = {1.0, 2.0};
    r.pairs.push_back(pr);
  }
  return r;
}

struct Fixture {
  Problem problem;
  Result result;
};

// Two bodies, one pair, two IterationReports and two adaptive steps (the lower body refined in step 1).
Fixture make_fixture() {
  Fixture f;
  Problem& pb = f.problem;
  pb.name = "fake";
  Body upper;
  upper.name = "upper";
  upper.material = {2.1e5, 0.3};
  upper.mesh = block(0, 1, 4, 2, 3, 2);
  Body lower;
  lower.name = "lower";
  lower.material = {2.1e5, 0.3};
  lower.mesh = block(0, 0, 4, 1, 4, 2);
  pb.bodies = {upper, lower};
  ContactPair cp;
  cp.name = "upper.bottom~lower.top";
  cp.slave_body = 0;
  cp.slave_edge = "bottom";
  cp.master_body = 1;
  cp.master_edge = "top";
  pb.contacts = {cp};
  pb.submitted = {{"name", "fake"}, {"bodies", nlohmann::json::array()}, {"note", "unicode \u00e9"}};
  pb.normalized = pb.submitted;
  pb.normalized["solver"] = {{"gamma", 0.02}};

  Result& r = f.result;
  r.converged = true;
  r.stop_reason = StopReason::converged;
  r.message = "converged after 2 iterations";
  r.iterations = 2;
  r.method = "neumann";
  r.gamma = 0.02;
  r.wall_seconds = 1.5;
  r.setup_seconds = 0.25;
  r.factorization_seconds = 0.125;

  Step s0;
  s0.index = 0;
  s0.iteration = 1;
  s0.bodies.push_back(body_field("upper", upper.mesh, false));
  s0.bodies.push_back(body_field("lower", lower.mesh, true));
  s0.pairs.push_back(pair_field(s0.bodies[0], 0.05));

  Step s1;
  s1.index = 1;
  s1.iteration = 2;
  mesh::Mesh refined = block(0, 0, 4, 1, 8, 4);
  std::fill(refined.level.begin(), refined.level.end(), 1);
  refined.level[0] = 2;
  s1.bodies.push_back(body_field("upper", upper.mesh, false));
  s1.bodies.push_back(body_field("lower", refined, true));
  s1.pairs.push_back(pair_field(s1.bodies[0], 0.04));

  r.history = {report(1, s0), report(2, s1)};
  r.steps = {s0, s1};
  return f;
}

template <class A, class B>
void expect_same(const A& a, const B& b, const std::string& what) {
  ASSERT_EQ(a.rows(), b.rows()) << what;
  ASSERT_EQ(a.cols(), b.cols()) << what;
  EXPECT_TRUE((a.array() == b.array()).all()) << what;
}

void expect_same_mesh(const mesh::Mesh& a, const mesh::Mesh& b, const std::string& what) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size()) << what;
  for (size_t i = 0; i < a.nodes.size(); ++i) EXPECT_EQ(a.nodes[i], b.nodes[i]) << what << " node " << i;
  EXPECT_EQ(a.cells, b.cells) << what;
  EXPECT_EQ(a.level, b.level) << what;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

size_t count(const std::string& text, const std::string& needle) {
  size_t n = 0;
  for (size_t pos = text.find(needle); pos != std::string::npos; pos = text.find(needle, pos + 1)) ++n;
  return n;
}

// A small well-formedness check: every element opened is closed in order, one root, declaration first.
bool xml_tags_balance(const std::string& text, std::string& problem) {
  std::vector<std::string> open;
  size_t roots = 0;
  for (size_t pos = text.find('<'); pos != std::string::npos; pos = text.find('<', pos + 1)) {
    const size_t end = text.find('>', pos);
    if (end == std::string::npos) return problem = "unterminated tag", false;
    const std::string tag = text.substr(pos + 1, end - pos - 1);
    if (tag.empty()) return problem = "empty tag", false;
    if (tag[0] == '?') {
      if (pos != 0) return problem = "declaration not first", false;
      continue;
    }
    if (tag[0] == '/') {
      const std::string name = tag.substr(1);
      if (open.empty() || open.back() != name) return problem = "unexpected </" + name + ">", false;
      open.pop_back();
      continue;
    }
    const std::string name = tag.substr(0, tag.find_first_of(" \t\n/"));
    if (open.empty()) ++roots;
    if (tag.back() != '/') open.push_back(name);
  }
  if (!open.empty()) return problem = "<" + open.back() + "> not closed", false;
  if (roots != 1) return problem = std::to_string(roots) + " root elements", false;
  return true;
}

}  // namespace

TEST(StopReason, NamesMatchTheEventVocabulary) {
  EXPECT_STREQ(to_string(StopReason::converged), "converged");
  EXPECT_STREQ(to_string(StopReason::max_iterations), "max_iterations");
  EXPECT_STREQ(to_string(StopReason::stagnation), "stagnation");
  EXPECT_STREQ(to_string(StopReason::cancelled), "cancelled");
  EXPECT_STREQ(to_string(StopReason::error), "error");
}

TEST(ResultFile, ReadBackEqualsWhatWasWritten) {
  const Fixture f = make_fixture();
  const fs::path path = output_dir() / "roundtrip.hdf";
  io::WriteInfo info;
  info.job_id = "1b4e28ba-2fa1-11d2-883f-0016d3cca427";
  info.created = "2024-05-01T12:00:00Z";
  info.host = "test-host";
  io::write_result(path.string(), f.problem, f.result, info);
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));

  const io::ResultFile r = io::read_result(path.string());
  EXPECT_EQ(r.format, "contact-ddm-result");
  EXPECT_EQ(r.format_version, 3);
  EXPECT_EQ(r.solver_version, CONTACT_VERSION);
  EXPECT_EQ(r.job_id, info.job_id);
  EXPECT_EQ(r.job_name, "fake");
  EXPECT_EQ(r.created, info.created);
  EXPECT_EQ(r.wall_seconds, 1.5);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.stop_reason, "converged");
  EXPECT_EQ(r.message, f.result.message);
  EXPECT_EQ(r.iterations, 2);
  EXPECT_EQ(r.method, "neumann");

  EXPECT_EQ(nlohmann::json::parse(r.job_json), f.problem.submitted);
  EXPECT_EQ(nlohmann::json::parse(r.normalized_json), f.problem.normalized);

  EXPECT_EQ(r.provenance.solver_version, CONTACT_VERSION);
  EXPECT_FALSE(r.provenance.compiler.empty());
  EXPECT_FALSE(r.provenance.build_type.empty());
  EXPECT_EQ(r.provenance.host, "test-host");
  EXPECT_EQ(r.provenance.method, "neumann");
  EXPECT_EQ(r.provenance.gamma, 0.02);
  EXPECT_EQ(r.provenance.setup_seconds, 0.25);
  EXPECT_EQ(r.provenance.factorization_seconds, 0.125);
  EXPECT_EQ(r.provenance.wall_seconds, 1.5);
  EXPECT_EQ(r.provenance.pair_names, std::vector<std::string>{"upper.bottom~lower.top"});
  EXPECT_EQ(r.provenance.theta, std::vector<double>{0.04});

  // /history/iterations: one row per report, columns in report order.
  const io::IterationHistory& h = r.history;
  const auto& reports = f.result.history;
  EXPECT_EQ(h.body_names, (std::vector<std::string>{"upper", "lower"}));
  EXPECT_EQ(h.pair_names, std::vector<std::string>{"upper.bottom~lower.top"});
  ASSERT_EQ(h.iteration.size(), 2u);
  ASSERT_EQ(h.elements.rows(), 2);
  ASSERT_EQ(h.elements.cols(), 2);
  ASSERT_EQ(h.force.rows(), 2);
  ASSERT_EQ(h.force.cols(), 1);
  for (size_t i = 0; i < reports.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    EXPECT_EQ(h.iteration[i], reports[i].iteration);
    EXPECT_EQ(h.paper_criterion[i], reports[i].paper_criterion);
    EXPECT_EQ(h.fixed_point_residual[i], reports[i].fixed_point_residual);
    EXPECT_EQ(h.complementarity[i], reports[i].complementarity);
    EXPECT_EQ(h.active_nodes_total[i], reports[i].active_nodes);
    EXPECT_EQ(h.active_set_changes[i], reports[i].active_set_changes);
    EXPECT_EQ(h.update[i], reports[i].update);
    EXPECT_EQ(h.elapsed_seconds[i], reports[i].elapsed_seconds);
    for (size_t b = 0; b < 2; ++b) {
      const auto col = static_cast<Eigen::Index>(b);
      EXPECT_EQ(h.elements(row, col), reports[i].bodies[b].elements);
      EXPECT_EQ(h.dofs(row, col), reports[i].bodies[b].dofs);
      EXPECT_EQ(h.elements_refined(row, col), reports[i].bodies[b].elements_refined);
    }
    const PairReport& p = reports[i].pairs[0];
    EXPECT_EQ(h.force(row, 0), p.force);
    EXPECT_EQ(h.max_pressure(row, 0), p.max_pressure);
    EXPECT_EQ(h.extent_begin(row, 0), p.extent_begin);
    EXPECT_EQ(h.extent_end(row, 0), p.extent_end);
    EXPECT_EQ(h.active_nodes(row, 0), p.active_nodes);
    EXPECT_EQ(h.changed_nodes(row, 0), p.changed_nodes);
    EXPECT_EQ(h.theta(row, 0), p.theta);
    EXPECT_EQ(h.max_penetration(row, 0), p.max_penetration);
  }

  // /history/steps
  const io::StepHistory& sh = r.step_history;
  EXPECT_EQ(sh.body_names, (std::vector<std::string>{"upper", "lower"}));
  EXPECT_EQ(sh.step, (std::vector<int>{0, 1}));
  EXPECT_EQ(sh.iteration, (std::vector<int>{1, 2}));
  ASSERT_EQ(sh.elements.rows(), 2);
  for (Eigen::Index k = 0; k < 2; ++k)
    for (Eigen::Index b = 0; b < 2; ++b) {
      const auto& m = f.result.steps[static_cast<size_t>(k)].bodies[static_cast<size_t>(b)].mesh;
      EXPECT_EQ(sh.elements(k, b), m.num_cells());
      EXPECT_EQ(sh.dofs(k, b), 2 * m.num_nodes());
    }

  // /steps/<k>: every field of every body and pair.
  ASSERT_EQ(r.steps.size(), f.result.steps.size());
  for (size_t k = 0; k < r.steps.size(); ++k) {
    const Step& got = r.steps[k];
    const Step& want = f.result.steps[k];
    EXPECT_EQ(got.index, static_cast<int>(k));
    EXPECT_EQ(got.iteration, want.iteration);
    ASSERT_EQ(got.bodies.size(), want.bodies.size());
    for (size_t b = 0; b < got.bodies.size(); ++b) {
      const BodyField& g = got.bodies[b];
      const BodyField& w = want.bodies[b];
      const std::string at = "step " + std::to_string(k) + " body " + w.name;
      EXPECT_EQ(g.name, w.name);
      expect_same_mesh(g.mesh, w.mesh, at);
      expect_same(g.displacement, w.displacement, at + " displacement");
      expect_same(g.stress_cell, w.stress_cell, at + " stress_cell");
      expect_same(g.stress_node, w.stress_node, at + " stress_node");
      expect_same(g.von_mises_cell, w.von_mises_cell, at + " von_mises");
      expect_same(g.indicator_cell, w.indicator_cell, at + " indicator");
      expect_same(g.reaction, w.reaction, at + " reaction");
    }
    ASSERT_EQ(got.pairs.size(), 1u);
    const PairField& g = got.pairs[0];
    const PairField& w = want.pairs[0];
    EXPECT_EQ(g.name, w.name);
    EXPECT_EQ(g.slave_body, w.slave_body);
    EXPECT_EQ(g.slave_edge, w.slave_edge);
    EXPECT_EQ(g.master_body, w.master_body);
    EXPECT_EQ(g.master_edge, w.master_edge);
    EXPECT_EQ(g.enforcement, w.enforcement);
    EXPECT_EQ(g.theta, w.theta);
    EXPECT_EQ(g.force, w.force);
    expect_same(g.node, w.node, "node");
    expect_same(g.position, w.position, "position");
    expect_same(g.normal, w.normal, "normal");
    expect_same(g.arc_length, w.arc_length, "arc_length");
    expect_same(g.weight, w.weight, "weight");
    expect_same(g.status, w.status, "status");
    expect_same(g.gap, w.gap, "gap");
    expect_same(g.normal_gap, w.normal_gap, "normal_gap");
    expect_same(g.pressure, w.pressure, "pressure");
    expect_same(g.penetration, w.penetration, "penetration");
    expect_same(g.active, w.active, "active");
    EXPECT_GT(g.active.sum(), 0);  // the fixture does have contact
  }
}

TEST(ResultFile, VtkHdfPartitionsOneBodyEachThenOnePairEachAndSizesAgree) {
  const Fixture f = make_fixture();
  const fs::path path = output_dir() / "vtkhdf.hdf";
  io::write_result(path.string(), f.problem, f.result);
  const io::ResultFile r = io::read_result(path.string());
  const io::VtkHdf& v = r.vtkhdf;
  const Step& last = f.result.steps.back();

  ASSERT_TRUE(v.present);
  EXPECT_EQ(v.version, (std::vector<std::int64_t>{1, 0}));
  EXPECT_EQ(v.type, "UnstructuredGrid");
  EXPECT_TRUE(v.type_storage.fixed_length);
  EXPECT_EQ(v.type_storage.size, 16u);  // no terminator counted: ParaView 5.11 compares all stored bytes

  const size_t partitions = last.bodies.size() + last.pairs.size();
  ASSERT_EQ(v.number_of_points.size(), partitions);
  ASSERT_EQ(v.number_of_cells.size(), partitions);
  ASSERT_EQ(v.number_of_connectivity_ids.size(), partitions);
  std::int64_t points = 0, cells = 0, ids = 0;
  size_t offset_at = 0;
  for (size_t b = 0; b < last.bodies.size(); ++b) {
    const mesh::Mesh& m = last.bodies[b].mesh;
    EXPECT_EQ(v.number_of_points[b], m.num_nodes());
    EXPECT_EQ(v.number_of_cells[b], m.num_cells());
    EXPECT_EQ(v.number_of_connectivity_ids[b], 4 * m.num_cells());
    // Each partition's offsets run from 0 to its own connectivity length; its ids are partition-local.
    ASSERT_LE(offset_at + static_cast<size_t>(m.num_cells()) + 1, v.offsets.size());
    EXPECT_EQ(v.offsets[offset_at], 0);
    EXPECT_EQ(v.offsets[offset_at + static_cast<size_t>(m.num_cells())], v.number_of_connectivity_ids[b]);
    for (std::int64_t k = 0; k < v.number_of_connectivity_ids[b]; ++k) {
      const std::int64_t id = v.connectivity[static_cast<size_t>(ids + k)];
      EXPECT_GE(id, 0);
      EXPECT_LT(id, v.number_of_points[b]);
    }
    for (Eigen::Index i = 0; i < m.num_nodes(); ++i) {
      EXPECT_EQ(v.points(points + i, 0), m.nodes[static_cast<size_t>(i)].x());
      EXPECT_EQ(v.points(points + i, 1), m.nodes[static_cast<size_t>(i)].y());
      EXPECT_EQ(v.points(points + i, 2), 0.0);
    }
    for (Eigen::Index e = 0; e < m.num_cells(); ++e)
      EXPECT_EQ(v.cell_data.at("body_id")(cells + e, 0), static_cast<double>(b));
    points += v.number_of_points[b];
    cells += v.number_of_cells[b];
    ids += v.number_of_connectivity_ids[b];
    offset_at += static_cast<size_t>(v.number_of_cells[b]) + 1;
  }
  const std::int64_t body_points = points, body_cells = cells;
  EXPECT_TRUE(std::all_of(v.types.begin(), v.types.begin() + body_cells, [](std::uint8_t t) { return t == 9; }));
  // The contact partitions: the slave polyline as lines, with the pair's pressure and active flags.
  for (size_t k = 0; k < last.pairs.size(); ++k) {
    const PairField& p = last.pairs[k];
    const size_t part = last.bodies.size() + k;
    const Eigen::Index n = p.position.rows();
    EXPECT_EQ(v.number_of_points[part], n);
    EXPECT_EQ(v.number_of_cells[part], n - 1);
    EXPECT_EQ(v.number_of_connectivity_ids[part], 2 * (n - 1));
    for (Eigen::Index j = 0; j < n; ++j) {
      EXPECT_EQ(v.points(points + j, 0), p.position(j, 0));
      EXPECT_EQ(v.point_data.at("pressure")(points + j, 0), p.pressure[j]);
      EXPECT_EQ(v.point_data.at("active")(points + j, 0), p.active[j]);
      // The slave body's displacement at that node.
      EXPECT_EQ(v.point_data.at("displacement")(points + j, 1), last.bodies[0].displacement(p.node[j], 1));
    }
    for (Eigen::Index e = 0; e < n - 1; ++e) {
      EXPECT_EQ(v.types[static_cast<size_t>(cells + e)], 3);  // VTK_LINE
      EXPECT_EQ(v.cell_data.at("pair_id")(cells + e, 0), static_cast<double>(k));
      EXPECT_EQ(v.cell_data.at("body_id")(cells + e, 0), -1.0);
    }
    points += n;
    cells += n - 1;
    ids += 2 * (n - 1);
    offset_at += static_cast<size_t>(n);
  }
  EXPECT_EQ(v.points.rows(), points);
  EXPECT_EQ(static_cast<std::int64_t>(v.connectivity.size()), ids);
  EXPECT_EQ(v.offsets.size(), offset_at);
  EXPECT_EQ(static_cast<std::int64_t>(v.types.size()), cells);
  // Body points are no contact points: pressure NaN, active -1.
  EXPECT_TRUE(std::isnan(v.point_data.at("pressure")(0, 0)));
  EXPECT_EQ(v.point_data.at("active")(0, 0), -1.0);

  const Eigen::MatrixXd& u = v.point_data.at("displacement");
  ASSERT_EQ(u.rows(), points);
  ASSERT_EQ(u.cols(), 3);
  EXPECT_EQ(u.col(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(u(0, 0), last.bodies[0].displacement(0, 0));
  EXPECT_EQ(v.point_data.at("stress").cols(), 6);  // VTK's symmetric tensor: ParaView names its components
  EXPECT_EQ(v.cell_data.at("stress").rows(), cells);
  EXPECT_EQ(v.cell_data.at("stress").cols(), 6);
  EXPECT_EQ(v.cell_data.at("von_mises").rows(), cells);
  const Eigen::MatrixXd& level = v.cell_data.at("level");
  EXPECT_EQ(level(body_cells - 1, 0), 1.0);  // the refined lower body is the last body
  // Only the lower body has an indicator: the upper body's cells are NaN, not a made-up 0.
  const Eigen::MatrixXd& indicator = v.cell_data.at("indicator");
  EXPECT_TRUE(std::isnan(indicator(0, 0)));
  EXPECT_EQ(indicator(body_cells - 1, 0), last.bodies[1].indicator_cell(last.bodies[1].indicator_cell.size() - 1));
  (void)body_points;
}

TEST(ResultFile, CreatedAndHostAreFilledWhenNotGiven) {
  const Fixture f = make_fixture();
  const fs::path path = output_dir() / "defaults.hdf";
  io::write_result(path.string(), f.problem, f.result);
  const io::ResultFile r = io::read_result(path.string());
  EXPECT_TRUE(std::regex_match(r.created, std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)"))) << r.created;
  EXPECT_FALSE(r.provenance.host.empty());
  EXPECT_EQ(r.job_id, "");
}

TEST(ResultFile, ResultWithoutStepsOrHistoryIsStillAFile) {
  Fixture f = make_fixture();
  f.result.steps.clear();
  f.result.history.clear();
  f.result.converged = false;
  f.result.stop_reason = StopReason::error;
  f.result.message = "body 'lower' is singular";
  const fs::path path = output_dir() / "empty.hdf";
  io::write_result(path.string(), f.problem, f.result);
  const io::ResultFile r = io::read_result(path.string());
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.stop_reason, "error");
  EXPECT_EQ(r.message, f.result.message);
  EXPECT_TRUE(r.steps.empty());
  EXPECT_TRUE(r.history.iteration.empty());
  EXPECT_EQ(r.history.body_names, (std::vector<std::string>{"upper", "lower"}));
  EXPECT_EQ(r.history.elements.rows(), 0);
  EXPECT_EQ(r.history.elements.cols(), 2);
  EXPECT_FALSE(r.vtkhdf.present);
}

TEST(ResultFile, UnwritablePathThrowsNamingThePathAndLeavesNoFile) {
  const Fixture f = make_fixture();
  const std::string path = (output_dir() / "no-such-dir" / "result.hdf").string();
  try {
    io::write_result(path, f.problem, f.result);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("create the file"), std::string::npos) << message;
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST(ResultFile, FailedRenameRemovesTheTemporaryFileAndKeepsTheTarget) {
  const Fixture f = make_fixture();
  // The target is a non-empty directory: the HDF5 file is written, but the final rename must fail.
  const fs::path target = output_dir() / "occupied.hdf";
  fs::create_directories(target / "keep");
  EXPECT_THROW(io::write_result(target.string(), f.problem, f.result), std::runtime_error);
  EXPECT_FALSE(fs::exists(target.string() + ".tmp"));
  EXPECT_TRUE(fs::is_directory(target / "keep"));
}

TEST(ResultFile, InconsistentFieldIsRefusedBeforeAnythingIsPublished) {
  Fixture f = make_fixture();
  f.result.steps[1].bodies[1].displacement.conservativeResize(3, 2);
  const fs::path path = output_dir() / "inconsistent.hdf";
  fs::remove(path);
  try {
    io::write_result(path.string(), f.problem, f.result);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("step 1 body 'lower': displacement has 3 rows"), std::string::npos) << message;
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
}

TEST(ResultFile, ReadingSomethingElseThrowsNamingThePath) {
  const fs::path text = output_dir() / "not-hdf5.hdf";
  std::ofstream(text) << "hello\n";
  try {
    io::read_result(text.string());
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(text.string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(io::read_result((output_dir() / "missing.hdf").string()), std::runtime_error);
}

TEST(ResultFile, ConcurrentWritersOfDifferentFilesDoNotInterfere) {
  // The server's workers write results from several threads at once (Debian's libhdf5 is thread-safe).
  const Fixture f = make_fixture();
  std::vector<std::string> errors(4);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < errors.size(); ++t)
    threads.emplace_back([&, t] {
      try {
        for (int rep = 0; rep < 5; ++rep) {
          const std::string path = (output_dir() / ("thread" + std::to_string(t) + ".hdf")).string();
          io::WriteInfo info;
          info.job_id = "job-" + std::to_string(t);
          io::write_result(path, f.problem, f.result, info);
          if (io::read_result(path).job_id != info.job_id) errors[t] = "read back another job id";
        }
      } catch (const std::exception& e) {
        errors[t] = e.what();
      }
    });
  for (auto& th : threads) th.join();
  for (const auto& e : errors) EXPECT_EQ(e, "");
}

TEST(ResultFile, PairsOfEveryKindRoundTripThroughTheStepsContactTables) {
  // Three pairs in each step: the fixture's frictionless one, a Tresca pair on the same slave nodes with its own
  // tangential fields, and a pair with no slave node at all. The tables (format version 3) hold them one after the
  // other: the offsets count each pair's rows, `pair` names each row's pair, the segments index the tables' rows,
  // and read_result gives back every pair's fields as written (a frictionless pair's friction fields empty).
  Fixture f = make_fixture();
  for (auto& s : f.result.steps) {
    PairField tresca = s.pairs[0];
    tresca.name = "tresca";
    tresca.friction = "tresca";
    tresca.friction_bound = 0.125;
    const Eigen::Index n = tresca.position.rows();
    tresca.tangent = Eigen::MatrixX2d(n, 2);
    tresca.tangent.col(0).setConstant(1.0);
    tresca.tangent.col(1).setZero();
    tresca.tangential_traction = Eigen::VectorXd::LinSpaced(n, -0.125, 0.125);
    tresca.slip = Eigen::VectorXd::LinSpaced(n, 0.0, 1e-3);
    tresca.slip[0] = std::numeric_limits<double>::quiet_NaN();  // the crosspoint (status 2)
    tresca.stick = Eigen::VectorXi::Ones(n);
    tresca.stick[n - 1] = 0;
    tresca.tangential_force = 0.0625;
    tresca.resultant = Eigen::Vector2d(0.0625, tresca.force);
    PairField empty = pair_field(s.bodies[0], 0.05);
    empty.name = "empty";
    for (auto* v : {&empty.arc_length, &empty.weight, &empty.gap, &empty.normal_gap, &empty.pressure, &empty.penetration})
      v->resize(0);
    empty.node.resize(0);
    empty.active.resize(0);
    empty.status.resize(0);
    empty.position.resize(0, 2);
    empty.normal.resize(0, 2);
    empty.force = 0.0;
    s.pairs.push_back(tresca);
    s.pairs.push_back(empty);
  }
  f.result.history = {report(1, f.result.steps[0]), report(2, f.result.steps[1])};
  const fs::path path = output_dir() / "pair_tables.hdf";
  io::write_result(path.string(), f.problem, f.result);

  const Eigen::Index n = f.result.steps[1].pairs[0].position.rows();
  {
    io::h5::Handle file = io::h5::open_file(path.string());
    io::h5::Handle g = io::h5::open_group(file, "steps/1/contacts");
    EXPECT_EQ(io::h5::read_vector<std::int64_t>(g, "offsets"), (std::vector<std::int64_t>{0, n, 2 * n, 2 * n}));
    EXPECT_EQ(io::h5::read_vector<std::int64_t>(g, "segment_offsets"),
              (std::vector<std::int64_t>{0, n - 1, 2 * n - 2, 2 * n - 2}));
    const auto pair = io::h5::read_vector<std::int32_t>(g, "pair");
    ASSERT_EQ(pair.size(), static_cast<size_t>(2 * n));
    for (Eigen::Index j = 0; j < 2 * n; ++j) EXPECT_EQ(pair[static_cast<size_t>(j)], j < n ? 0 : 1);
    std::vector<hsize_t> dims;
    const auto segments = io::h5::read_dataset<std::int64_t>(g, "segments", 2, dims);
    ASSERT_EQ(dims, (std::vector<hsize_t>{static_cast<hsize_t>(2 * n - 2), 2}));
    EXPECT_EQ(segments[static_cast<size_t>(2 * (n - 1))], n);  // the Tresca pair's first segment: its own rows
    EXPECT_EQ(io::h5::read_strings_dataset(g, "friction"), (std::vector<std::string>{"none", "tresca", "none"}));
    // A frictionless pair's rows: no traction, no slip measured, not sticking.
    const auto slip = io::h5::read_vector<double>(g, "slip");
    EXPECT_TRUE(std::isnan(slip[1]));
    EXPECT_EQ(io::h5::read_vector<double>(g, "tangential_traction")[1], 0.0);
  }

  const io::ResultFile r = io::read_result(path.string());
  ASSERT_EQ(r.steps.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    ASSERT_EQ(r.steps[k].pairs.size(), 3u);
    for (size_t p = 0; p < 3; ++p) {
      const PairField& g = r.steps[k].pairs[p];
      const PairField& w = f.result.steps[k].pairs[p];
      const std::string at = "step " + std::to_string(k) + " pair " + w.name + " ";
      EXPECT_EQ(g.name, w.name);
      EXPECT_EQ(g.slave_body + g.slave_edge + g.master_body + g.master_edge + g.enforcement,
                w.slave_body + w.slave_edge + w.master_body + w.master_edge + w.enforcement);
      EXPECT_EQ(g.theta, w.theta);
      EXPECT_EQ(g.force, w.force);
      EXPECT_EQ(g.resultant, w.resultant);
      expect_same(g.node, w.node, at + "node");
      expect_same(g.position, w.position, at + "position");
      expect_same(g.normal, w.normal, at + "normal");
      expect_same(g.arc_length, w.arc_length, at + "arc_length");
      expect_same(g.weight, w.weight, at + "weight");
      expect_same(g.status, w.status, at + "status");
      expect_same(g.pressure, w.pressure, at + "pressure");
      expect_same(g.active, w.active, at + "active");
      EXPECT_EQ(g.friction, w.friction);
      EXPECT_EQ(g.friction_bound, w.friction_bound);
      EXPECT_EQ(g.tangential_force, w.tangential_force);
      expect_same(g.tangent, w.tangent, at + "tangent");
      expect_same(g.tangential_traction, w.tangential_traction, at + "tangential_traction");
      expect_same(g.stick, w.stick, at + "stick");
      ASSERT_EQ(g.slip.size(), w.slip.size()) << at;
      EXPECT_TRUE(((g.slip.array() == w.slip.array()) || (g.slip.array().isNaN() && w.slip.array().isNaN())).all())
          << at;
    }
  }
}

TEST(ResultFile, AVersion2FileReadsAsTheSameJobSolvedAndWrittenNow) {
  // tests/data/result_format_v2.hdf: tests/data/result_format_v2.json (stack3 coarsened, Coulomb on one pair, the
  // other frictionless, two load steps, the last kept) solved and written by commit 68ed5ab, the last writer of
  // format version 2 (a group per pair). read_result reads it into what the same job gives now through the
  // version 3 tables: the same pairs, the friction fields on the Coulomb pair only, the same values.
  const std::string dir = std::string(CONTACT_SOURCE_DIR) + "/tests/data/";
  const io::ResultFile old = io::read_result(dir + "result_format_v2.hdf");
  EXPECT_EQ(old.format_version, 2);
  std::ifstream in(dir + "result_format_v2.json");
  const auto parsed = job::parse(nlohmann::json::parse(in));
  ASSERT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  Observer quiet;
  CancelToken cancel;
  Result result = solve(*parsed.problem, quiet, cancel);
  ASSERT_TRUE(result.converged) << result.message;
  const fs::path hdf = output_dir() / "version3.hdf";
  io::write_result(hdf.string(), *parsed.problem, result);
  const io::ResultFile now = io::read_result(hdf.string());
  ASSERT_EQ(old.steps.size(), 1u);
  ASSERT_EQ(now.steps.size(), 1u);
  const auto& a = old.steps[0].pairs;
  const auto& b = now.steps[0].pairs;
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  auto close = [](const auto& x, const auto& y) {
    return x.rows() == y.rows() && x.cols() == y.cols() &&
           (x.size() == 0 || (x - y).cwiseAbs().maxCoeff() <= 1e-6 * std::max(1.0, y.cwiseAbs().maxCoeff()));
  };
  for (size_t p = 0; p < 2; ++p) {
    const std::string at = "pair " + b[p].name;
    EXPECT_EQ(a[p].name, b[p].name);
    EXPECT_EQ(a[p].slave_body + a[p].slave_edge + a[p].master_body + a[p].master_edge,
              b[p].slave_body + b[p].slave_edge + b[p].master_body + b[p].master_edge);
    EXPECT_EQ(a[p].friction, b[p].friction) << at;
    EXPECT_EQ(a[p].node, b[p].node) << at;
    EXPECT_EQ(a[p].status, b[p].status) << at;
    EXPECT_EQ(a[p].active, b[p].active) << at;
    EXPECT_TRUE(close(a[p].position, b[p].position)) << at;
    EXPECT_TRUE(close(a[p].weight, b[p].weight)) << at;
    EXPECT_TRUE(close(a[p].pressure, b[p].pressure)) << at;
    EXPECT_NEAR(a[p].force, b[p].force, 1e-6 * std::abs(b[p].force)) << at;
    EXPECT_TRUE(close(a[p].resultant, b[p].resultant)) << at;
    EXPECT_TRUE(close(a[p].tangential_traction, b[p].tangential_traction)) << at;
    EXPECT_EQ(a[p].stick, b[p].stick) << at;
    EXPECT_EQ(a[p].tangent.rows(), b[p].tangent.rows()) << at;
  }
  // One pair of each kind: the frictionless one's friction fields empty, the Coulomb one's present and sticking
  // somewhere.
  const PairField& coulomb = a[0].friction == "coulomb" ? a[0] : a[1];
  const PairField& plain = a[0].friction == "coulomb" ? a[1] : a[0];
  EXPECT_EQ(plain.friction, "none");
  EXPECT_EQ(plain.tangential_traction.size(), 0);
  EXPECT_EQ(coulomb.friction_coefficient, 0.3);
  EXPECT_GT(coulomb.stick.sum(), 0);
}

TEST(Xdmf, SidecarIsWellFormedAndNamesEveryStepBodyAndContactSurface) {
  const Fixture f = make_fixture();
  const fs::path hdf = output_dir() / "sidecar.hdf";
  io::write_result(hdf.string(), f.problem, f.result);
  const std::string xmf = io::xdmf_path_for(hdf.string());
  EXPECT_EQ(fs::path(xmf).filename(), "sidecar.xmf");
  io::write_xdmf(xmf, hdf.filename().string(), f.result);
  EXPECT_FALSE(fs::exists(xmf + ".tmp"));

  const std::string text = read_text(xmf);
  std::string problem;
  EXPECT_TRUE(xml_tags_balance(text, problem)) << problem;
  EXPECT_NE(text.find("CollectionType=\"Temporal\""), std::string::npos);
  for (size_t k = 0; k < f.result.steps.size(); ++k) {
    EXPECT_NE(text.find("<Time Value=\"" + std::to_string(k) + "\"/>"), std::string::npos) << k;
    for (const auto& b : f.result.steps[k].bodies) {
      const std::string base = "sidecar.hdf:/steps/" + std::to_string(k) + "/bodies/" + b.name;
      EXPECT_NE(text.find(base + "/points</DataItem>"), std::string::npos) << base;
      EXPECT_NE(text.find(base + "/quads</DataItem>"), std::string::npos) << base;
      EXPECT_NE(text.find(base + "/displacement</DataItem>"), std::string::npos) << base;
      EXPECT_NE(text.find(base + "/von_mises</DataItem>"), std::string::npos) << base;
      EXPECT_NE(text.find(base + "/level</DataItem>"), std::string::npos) << base;
    }
    // The contact surfaces of all pairs as one grid: the slave polylines with pressure, gap, active and the pair.
    const std::string base = "sidecar.hdf:/steps/" + std::to_string(k) + "/contacts";
    for (const char* array : {"/segments", "/position", "/pressure", "/normal_gap", "/active", "/pair"})
      EXPECT_NE(text.find(base + array + "</DataItem>"), std::string::npos) << base << array;
  }
  EXPECT_EQ(count(text, "TopologyType=\"Polyline\""), f.result.steps.size());
  EXPECT_EQ(count(text, "<Grid Name=\"contacts\""), f.result.steps.size());
  EXPECT_EQ(count(text, "<Grid Name=\"upper\""), f.result.steps.size());
  EXPECT_EQ(count(text, "<Grid Name=\"lower\""), f.result.steps.size());
  EXPECT_EQ(count(text, "/indicator</DataItem>"), f.result.steps.size());  // lower body only
  EXPECT_EQ(io::xdmf_path_for("a/b.h5"), "a/b.h5.xmf");
}

TEST(ResultFile, TriangleAndMixedMeshesRoundTripAndTheViewsTypeEveryCell) {
  // The fixture with the upper body all triangles and the refined lower body mixed: `cells` and `cell_types`
  // for every body, `quads` only for an all-quadrilateral mesh, VTK_TRIANGLE (5) and VTK_QUAD (9) in /VTKHDF,
  // XDMF's Mixed topology in the sidecar, and the meshes read back cell for cell.
  Fixture f = make_fixture();
  for (auto& s : f.result.steps) {
    s.bodies[0] = body_field("upper", contact::testing::split_into_triangles(s.bodies[0].mesh), false);
    s.bodies[1] = body_field("lower", contact::testing::split_into_triangles(s.bodies[1].mesh, [](int c) { return c % 3 == 0; }),
                             true);
    s.pairs[0] = pair_field(s.bodies[0], 0.04);
  }
  f.result.history = {report(1, f.result.steps[0]), report(2, f.result.steps[1])};
  const fs::path path = output_dir() / "triangles.hdf";
  io::write_result(path.string(), f.problem, f.result);
  const io::ResultFile r = io::read_result(path.string());
  ASSERT_EQ(r.steps.size(), 2u);
  for (size_t k = 0; k < 2; ++k)
    for (size_t b = 0; b < 2; ++b)
      expect_same_mesh(r.steps[k].bodies[b].mesh, f.result.steps[k].bodies[b].mesh, "step " + std::to_string(k));
  const Step& last = f.result.steps.back();
  const io::VtkHdf& v = r.vtkhdf;
  size_t cell = 0, id = 0;
  for (size_t b = 0; b < 2; ++b) {
    const mesh::Mesh& m = last.bodies[b].mesh;
    std::int64_t ids = 0;
    for (const auto& c : m.cells) {
      EXPECT_EQ(v.types[cell], c.is_triangle() ? 5 : 9) << "body " << b;
      for (int node : c) EXPECT_EQ(v.connectivity[id++], node);
      ids += c.size();
      ++cell;
    }
    EXPECT_EQ(v.number_of_connectivity_ids[b], ids);
  }
  EXPECT_EQ(std::count(v.types.begin(), v.types.end(), 5),
            std::count_if(last.bodies[0].mesh.cells.begin(), last.bodies[0].mesh.cells.end(), [](const mesh::Cell& c) { return c.is_triangle(); }) +
                std::count_if(last.bodies[1].mesh.cells.begin(), last.bodies[1].mesh.cells.end(), [](const mesh::Cell& c) { return c.is_triangle(); }));
  // Stresses in the views: VTK's symmetric tensor (xx, yy, zz, xy, yz, xz) of (sxx, syy, sxy, szz).
  const Eigen::MatrixXd& s = v.cell_data.at("stress");
  const Eigen::MatrixX4d& upper = last.bodies[0].stress_cell;
  for (Eigen::Index e = 0; e < upper.rows(); ++e) {
    EXPECT_EQ(s(e, 0), upper(e, 0));
    EXPECT_EQ(s(e, 1), upper(e, 1));
    EXPECT_EQ(s(e, 2), upper(e, 3));
    EXPECT_EQ(s(e, 3), upper(e, 2));
    EXPECT_EQ(s(e, 4), 0.0);
    EXPECT_EQ(s(e, 5), 0.0);
  }
  // The sidecar: Mixed topologies of 1 + nodes numbers per cell, on xdmf_topology; the stresses as tensors.
  const std::string xmf = io::xdmf_path_for(path.string());
  io::write_xdmf(xmf, path.filename().string(), f.result);
  const std::string text = read_text(xmf);
  std::string problem;
  EXPECT_TRUE(xml_tags_balance(text, problem)) << problem;
  EXPECT_EQ(count(text, "TopologyType=\"Mixed\""), 4u);
  EXPECT_EQ(count(text, "TopologyType=\"Quadrilateral\""), 0u);
  for (size_t b = 0; b < 2; ++b) {
    const mesh::Mesh& m = last.bodies[b].mesh;
    const size_t length = m.cells.size() + static_cast<size_t>(std::accumulate(
                                                m.cells.begin(), m.cells.end(), 0, [](int n, const mesh::Cell& c) { return n + c.size(); }));
    EXPECT_NE(text.find("<DataItem Dimensions=\"" + std::to_string(length) + "\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">"
                        "triangles.hdf:/steps/1/bodies/" + last.bodies[b].name + "/xdmf_topology</DataItem>"),
              std::string::npos)
        << last.bodies[b].name;
    EXPECT_NE(text.find("/steps/1/bodies/" + last.bodies[b].name + "/stress_node_tensor</DataItem>"), std::string::npos);
  }
}

TEST(Xdmf, LoadStepsAreTimedByTheirLoadFactor) {
  // ParaView's time axis of a load-stepped result is the load; adaptive steps (one load) keep their index.
  Fixture f = make_fixture();
  ASSERT_GE(f.result.steps.size(), 2u);
  for (size_t k = 0; k < f.result.steps.size(); ++k)
    f.result.steps[k].load_factor = static_cast<double>(k + 1) / static_cast<double>(f.result.steps.size() * 2);
  const fs::path hdf = output_dir() / "load_steps.hdf";
  const std::string xmf = io::xdmf_path_for(hdf.string());
  io::write_xdmf(xmf, hdf.filename().string(), f.result);
  const std::string text = read_text(xmf);
  for (size_t k = 0; k < f.result.steps.size(); ++k) {
    std::ostringstream value;
    value.precision(17);
    value << f.result.steps[k].load_factor;
    EXPECT_NE(text.find("<Time Value=\"" + value.str() + "\"/>"), std::string::npos) << value.str();
  }
}

// output.steps "last" (issue 23, item 3): of the paper's problem in 10 load steps the file keeps the last step's
// fields only, as /steps/0 with its row in the history, and /history/steps has every step; the numbers are those
// of the run that keeps every step.
TEST(ResultFile, OutputStepsLastKeepsTheLastStepsFieldsAndEveryStepsHistory) {
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/examples/seed_layers_steps.json");
  nlohmann::json job = nlohmann::json::parse(in);
  std::map<std::string, io::ResultFile> files;
  std::map<std::string, std::vector<std::string>> groups;
  for (const std::string keep : {"all", "last"}) {
    job["output"] = {{"steps", keep}};
    const auto parsed = job::parse(job);
    ASSERT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
    Observer quiet;
    CancelToken never;
    const Result r = solve(*parsed.problem, quiet, never);
    ASSERT_TRUE(r.converged) << r.message;
    const std::string path = (output_dir() / ("steps_" + keep + ".hdf")).string();
    io::write_result(path, *parsed.problem, r, {});
    files[keep] = io::read_result(path);
    io::h5::Handle file = io::h5::open_file(path);
    groups[keep] = io::h5::link_names(io::h5::open_group(file, "steps"));
  }
  const io::ResultFile& all = files["all"];
  const io::ResultFile& last = files["last"];
  ASSERT_EQ(all.steps.size(), 10u);
  EXPECT_EQ(groups["last"], std::vector<std::string>{"0"});
  ASSERT_EQ(last.steps.size(), 1u);
  EXPECT_EQ(last.steps[0].index, 9);  // its row in /history/steps
  EXPECT_EQ(last.steps[0].load_factor, 1.0);
  ASSERT_EQ(last.step_history.load_factor.size(), 10u);
  for (size_t k = 0; k < 10; ++k) EXPECT_NEAR(last.step_history.load_factor[k], (k + 1) / 10.0, 1e-15) << k;
  EXPECT_TRUE(last.step_history.force.isApprox(all.step_history.force, 1e-12));
  EXPECT_TRUE(last.step_history.contact_end.isApprox(all.step_history.contact_end, 1e-12));
  EXPECT_EQ(last.step_history.dofs, all.step_history.dofs);
  const PairField& kept = last.steps[0].pairs.at(0);
  EXPECT_TRUE(kept.pressure.isApprox(all.steps[9].pairs.at(0).pressure, 1e-12));
  EXPECT_NEAR(kept.force, last.step_history.force(9, 0), 1e-12 * kept.force);
  EXPECT_LT(last.step_history.force(0, 0), last.step_history.force(9, 0));
}

// The solver keeps in memory only what the file will hold: with StepOutput::last one step's fields at a time,
// and every step's scalars.
TEST(StepLog, LastKeepsOneStepsFieldsAndEveryStepsSummary) {
  ddm::StepLog log(StepOutput::last);
  for (int k = 0; k < 3; ++k) {
    Step s;
    s.index = k;
    s.load_factor = (k + 1) / 3.0;
    s.bodies.push_back(body_field("b", block(0, 0, 1, 1, k + 1, 1), false));
    log.push_back(std::move(s));
    EXPECT_EQ(log.back().index, k);
  }
  const auto steps = log.take_steps();
  const auto rows = log.take_summaries();
  ASSERT_EQ(steps.size(), 1u);
  EXPECT_EQ(steps[0].index, 2);
  ASSERT_EQ(rows.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(rows[static_cast<size_t>(k)].elements, std::vector<int>{k + 1});
    EXPECT_EQ(rows[static_cast<size_t>(k)].nodes, std::vector<int>{2 * (k + 2)});
  }
}

TEST(ResultFile, FrictionFieldsRoundTripAndShowInTheSidecarAndVtkhdf) {
  // The roller example: two Coulomb pairs in three load steps.
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/examples/roller_friction.json");
  const auto parsed = job::parse(nlohmann::json::parse(in));
  ASSERT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  Observer quiet;
  CancelToken cancel;
  const Result result = solve(*parsed.problem, quiet, cancel);
  ASSERT_TRUE(result.converged) << result.message;
  const fs::path hdf = output_dir() / "friction.hdf";
  io::write_result(hdf.string(), *parsed.problem, result);
  const std::string xmf = io::xdmf_path_for(hdf.string());
  io::write_xdmf(xmf, hdf.filename().string(), result);
  const auto back = io::read_result(hdf.string());
  ASSERT_EQ(back.steps.size(), result.steps.size());
  for (size_t k = 0; k < result.steps.size(); ++k)
    for (size_t p = 0; p < result.steps[k].pairs.size(); ++p) {
      const PairField& a = result.steps[k].pairs[p];
      const PairField& b = back.steps[k].pairs[p];
      EXPECT_EQ(b.friction, "coulomb");
      EXPECT_EQ(b.friction_coefficient, 0.2);
      EXPECT_EQ(b.tangential_force, a.tangential_force);
      EXPECT_EQ(b.tangent, a.tangent);
      EXPECT_EQ(b.tangential_traction, a.tangential_traction);
      EXPECT_EQ(b.stick, a.stick);
      EXPECT_TRUE(b.slip.isApprox(a.slip) || (b.slip.array().isNaN() == a.slip.array().isNaN()).all());
      EXPECT_EQ(back.step_history.tangential_force(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(p)),
                a.tangential_force);
    }
  // The last step sticks and slips somewhere: both flags occur.
  const PairField& last = back.steps.back().pairs[0];
  EXPECT_GT(last.stick.sum(), 0);
  EXPECT_LT(last.stick.sum(), last.active.sum());
  const std::string text = read_text(xmf);
  for (const char* name : {"tangential_traction", "slip", "stick", "tangent"})
    EXPECT_NE(text.find("<Attribute Name=\"" + std::string(name) + "\""), std::string::npos) << name;
  // ParaView's VTKHDF grid carries them too.
  io::h5::Handle file = io::h5::open_file(hdf.string());
  EXPECT_TRUE(io::h5::has_link(io::h5::open_group(file, "VTKHDF/PointData"), "tangential_traction"));
}

