#include "collapse_group.hpp"

#include "h5.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace contact::io {

namespace {

using h5::Handle;

// n x 2 points as one row-major dataset.
void write_points(hid_t g, const std::string& name, const std::vector<Eigen::Vector2d>& points) {
  std::vector<double> data;
  for (const auto& p : points) data.insert(data.end(), {p.x(), p.y()});
  h5::write_dataset(g, name, data, {points.size(), 2});
}

std::vector<Eigen::Vector2d> read_points(hid_t g, const std::string& name) {
  std::vector<hsize_t> dims;
  const auto data = h5::read_dataset<double>(g, name, 2, dims);
  std::vector<Eigen::Vector2d> out;
  for (hsize_t i = 0; i < dims[0]; ++i) out.emplace_back(data[2 * i], data[2 * i + 1]);
  return out;
}

void expect_rows(size_t rows, size_t n, const char* what) {
  if (rows != n)
    throw std::runtime_error(std::string("/collapse/mechanism: ") + what + " has " + std::to_string(rows) +
                             " rows for " + std::to_string(n) + " names");
}

void write_mechanism(hid_t g, const char* name, const Mechanism& mechanism) {
  Handle m = h5::create_group(g, name);
  h5::write_attribute(m, "kind", mechanism.kind);
  h5::write_attribute(m, "words", mechanism.words);
  h5::write_attribute(m, "source", mechanism.source);
  h5::write_attribute(m, "check", mechanism.check);
  std::vector<std::string> bodies, body_words, pairs, kinds, joint_words;
  std::vector<Eigen::Vector2d> velocity, reference, centre, point;
  std::vector<double> omega, slip, opening;
  for (const auto& b : mechanism.bodies) {
    bodies.push_back(b.body);
    body_words.push_back(b.words);
    velocity.push_back(b.velocity);
    reference.push_back(b.reference);
    centre.push_back(b.centre);
    omega.push_back(b.omega);
  }
  for (const auto& j : mechanism.joints) {
    pairs.push_back(j.pair);
    kinds.push_back(j.kind);
    joint_words.push_back(j.words);
    point.push_back(j.point);
    slip.push_back(j.slip);
    opening.push_back(j.opening);
  }
  h5::write_strings_dataset(m, "body_names", bodies);
  write_points(m, "body_velocity", velocity);
  h5::write_vector(m, "body_omega", omega);
  write_points(m, "body_reference", reference);
  write_points(m, "body_centre", centre);
  h5::write_strings_dataset(m, "body_words", body_words);
  h5::write_strings_dataset(m, "pair_names", pairs);
  h5::write_strings_dataset(m, "joint_kind", kinds);
  write_points(m, "joint_point", point);
  h5::write_vector(m, "joint_slip", slip);
  h5::write_vector(m, "joint_opening", opening);
  h5::write_strings_dataset(m, "joint_words", joint_words);
}

void read_mechanism(hid_t g, const char* name, Mechanism& mechanism) {
  Handle m = h5::open_group(g, name);
  mechanism.kind = h5::read_string_attribute(m, "kind");
  mechanism.words = h5::read_string_attribute(m, "words");
  if (h5::has_attribute(m, "source")) {  // (files from before the elastic mechanism: the statics')
    mechanism.source = h5::read_string_attribute(m, "source");
    mechanism.check = h5::read_string_attribute(m, "check");
  } else {
    mechanism.source = "statics";
  }
  const auto bodies = h5::read_strings_dataset(m, "body_names");
  const auto velocity = read_points(m, "body_velocity");
  const auto omega = h5::read_vector<double>(m, "body_omega");
  const auto reference = read_points(m, "body_reference");
  const auto centre = read_points(m, "body_centre");
  const auto body_words = h5::read_strings_dataset(m, "body_words");
  for (const auto& [v, what] : {std::pair{velocity.size(), "body_velocity"},
                                {omega.size(), "body_omega"},
                                {reference.size(), "body_reference"},
                                {centre.size(), "body_centre"},
                                {body_words.size(), "body_words"}})
    expect_rows(v, bodies.size(), what);
  for (size_t i = 0; i < bodies.size(); ++i)
    mechanism.bodies.push_back(BodyMotion{bodies[i], velocity[i], omega[i], reference[i], centre[i], body_words[i]});
  const auto pairs = h5::read_strings_dataset(m, "pair_names");
  const auto kinds = h5::read_strings_dataset(m, "joint_kind");
  const auto point = read_points(m, "joint_point");
  const auto slip = h5::read_vector<double>(m, "joint_slip");
  const auto opening = h5::read_vector<double>(m, "joint_opening");
  const auto joint_words = h5::read_strings_dataset(m, "joint_words");
  for (const auto& [v, what] : {std::pair{kinds.size(), "joint_kind"},
                                {point.size(), "joint_point"},
                                {slip.size(), "joint_slip"},
                                {opening.size(), "joint_opening"},
                                {joint_words.size(), "joint_words"}})
    expect_rows(v, pairs.size(), what);
  for (size_t i = 0; i < pairs.size(); ++i)
    mechanism.joints.push_back(JointMotion{pairs[i], kinds[i], point[i], slip[i], opening[i], joint_words[i]});
}

}  // namespace

void write_collapse(hid_t file, const CollapseResult& c) {
  if (!c.analysed) return;
  Handle g = h5::create_group(file, "collapse");
  h5::write_attribute(g, "verdict", c.verdict);
  h5::write_attribute<double>(g, "held", c.held);
  h5::write_attribute<double>(g, "failed", c.failed);
  h5::write_attribute<std::int32_t>(g, "failed_by_statics", c.failed_by_statics ? 1 : 0);
  h5::write_attribute<std::int32_t>(g, "failed_by_budget", c.failed_by_budget ? 1 : 0);
  h5::write_attribute<double>(g, "tolerance", c.tolerance);
  h5::write_attribute<std::int32_t>(g, "solves", c.solves);
  h5::write_attribute<std::int32_t>(g, "bracket_solves", c.bracket_solves);
  h5::write_attribute<double>(g, "statics_bound", c.statics_bound);
  h5::write_attribute<double>(g, "start_displacement", c.start_displacement);
  h5::write_attribute(g, "words", c.words);
  write_mechanism(g, "mechanism", c.mechanism);
  if (!c.statics_mechanism.kind.empty() || !c.statics_mechanism.words.empty())
    write_mechanism(g, "statics_mechanism", c.statics_mechanism);
  Handle t = h5::create_group(g, "trials");
  std::vector<double> lambda, seconds, displacement;
  std::vector<std::int8_t> held;
  std::vector<std::int32_t> iterations;
  for (const auto& trial : c.trials) {
    lambda.push_back(trial.multiplier);
    held.push_back(trial.held ? 1 : 0);
    iterations.push_back(trial.iterations);
    seconds.push_back(trial.seconds);
    displacement.push_back(trial.displacement);
  }
  h5::write_vector(t, "multiplier", lambda);
  h5::write_vector(t, "held", held);
  h5::write_vector(t, "iterations", iterations);
  h5::write_vector(t, "seconds", seconds);
  h5::write_vector(t, "displacement", displacement);
}

void read_collapse(hid_t file, CollapseResult& c) {
  if (!h5::has_link(file, "collapse")) return;
  Handle g = h5::open_group(file, "collapse");
  c.analysed = true;
  c.verdict = h5::read_string_attribute(g, "verdict");
  c.held = h5::read_attribute<double>(g, "held");
  c.failed = h5::read_attribute<double>(g, "failed");
  c.failed_by_statics = h5::read_attribute<std::int32_t>(g, "failed_by_statics") != 0;
  if (h5::has_attribute(g, "failed_by_budget"))  // (files from before it: none)
    c.failed_by_budget = h5::read_attribute<std::int32_t>(g, "failed_by_budget") != 0;
  c.tolerance = h5::read_attribute<double>(g, "tolerance");
  c.solves = h5::read_attribute<std::int32_t>(g, "solves");
  c.bracket_solves = h5::read_attribute<std::int32_t>(g, "bracket_solves");
  c.statics_bound = h5::read_attribute<double>(g, "statics_bound");
  if (h5::has_attribute(g, "start_displacement"))  // (files from before the capacity curve: none)
    c.start_displacement = h5::read_attribute<double>(g, "start_displacement");
  c.words = h5::read_string_attribute(g, "words");
  read_mechanism(g, "mechanism", c.mechanism);
  if (h5::has_link(g, "statics_mechanism")) read_mechanism(g, "statics_mechanism", c.statics_mechanism);
  if (!h5::has_link(g, "trials")) return;
  Handle t = h5::open_group(g, "trials");
  const auto lambda = h5::read_vector<double>(t, "multiplier");
  const auto held = h5::read_vector<std::int8_t>(t, "held");
  const auto iterations = h5::read_vector<std::int32_t>(t, "iterations");
  const auto seconds = h5::read_vector<double>(t, "seconds");
  // (files written before the capacity curve's displacement have none: NaN)
  const auto displacement = h5::has_link(t, "displacement") ? h5::read_vector<double>(t, "displacement")
                                                            : std::vector<double>(lambda.size(), std::nan(""));
  if (held.size() != lambda.size() || iterations.size() != lambda.size() || seconds.size() != lambda.size() ||
      displacement.size() != lambda.size())
    throw std::runtime_error("/collapse/trials: its datasets differ in length");
  for (size_t i = 0; i < lambda.size(); ++i)
    c.trials.push_back({lambda[i], held[i] != 0, iterations[i], seconds[i], displacement[i]});
}

}  // namespace contact::io
