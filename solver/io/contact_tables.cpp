// contact_tables: a step's contact pairs as tables in the result file (contact_tables.hpp, docs/results-format.md).
#include "contact_tables.hpp"

#include "h5.hpp"
#include "h5_eigen.hpp"
#include "view_layout.hpp"

#include <cstdint>
#include <limits>
#include <stdexcept>

namespace contact::io {

namespace {

using h5::Handle;
using h5::read_column;
using h5::read_matrix;

std::string rows_text(Eigen::Index n) { return std::to_string(static_cast<long long>(n)); }

// Every per-node field of a pair has the pair's node count (the friction fields too, when it has friction).
void check_pair_rows(const PairField& p, const std::string& where) {
  const Eigen::Index n = p.position.rows();
  const std::string at = where + " pair '" + p.name + "': ";
  auto same = [&](const std::string& what, Eigen::Index rows) {
    if (rows != n)
      throw std::runtime_error(at + what + " has " + rows_text(rows) + " rows, position has " + rows_text(n));
  };
  same("node", p.node.rows());
  same("normal", p.normal.rows());
  same("arc_length", p.arc_length.rows());
  same("weight", p.weight.rows());
  same("gap", p.gap.rows());
  same("normal_gap", p.normal_gap.rows());
  same("pressure", p.pressure.rows());
  same("penetration", p.penetration.rows());
  same("active", p.active.rows());
  same("status", p.status.rows());
  if (p.friction != "none") {
    same("tangent", p.tangent.rows());
    same("tangential_traction", p.tangential_traction.rows());
    same("slip", p.slip.rows());
    same("stick", p.stick.rows());
  }
}

// The tables of one step, filled pair by pair. Two-column quantities are row-major (N x 2), as HDF5 stores them.
struct Tables {
  // per node
  std::vector<std::int64_t> node;
  std::vector<std::int32_t> pair;
  std::vector<double> position, normal, tangent;
  std::vector<double> arc_length, weight, gap, normal_gap, pressure, penetration, tangential_traction, slip;
  std::vector<std::int8_t> active, status, stick;
  // per segment: rows of the node tables
  std::vector<std::int64_t> segments;
  // per pair
  std::vector<std::int64_t> offsets{0}, segment_offsets{0};
  std::vector<std::string> slave_body, slave_edge, master_body, master_edge, enforcement, friction;
  std::vector<double> theta, force, resultant, friction_coefficient, friction_bound, tangential_force;

  void add(const PairField& p, bool closed) {
    const Eigen::Index n = p.position.rows();
    const auto first = static_cast<std::int64_t>(node.size());
    const bool frictional = p.friction != "none";
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (Eigen::Index j = 0; j < n; ++j) {
      node.push_back(p.node[j]);
      pair.push_back(static_cast<std::int32_t>(offsets.size() - 1));
      position.insert(position.end(), {p.position(j, 0), p.position(j, 1)});
      normal.insert(normal.end(), {p.normal(j, 0), p.normal(j, 1)});
      arc_length.push_back(p.arc_length[j]);
      weight.push_back(p.weight[j]);
      gap.push_back(p.gap[j]);
      normal_gap.push_back(p.normal_gap[j]);
      pressure.push_back(p.pressure[j]);
      penetration.push_back(p.penetration[j]);
      active.push_back(static_cast<std::int8_t>(p.active[j]));
      status.push_back(static_cast<std::int8_t>(p.status[j]));
      // A frictionless pair's rows: its tangent (the normal turned a quarter anticlockwise), no traction, no slip
      // measured (NaN), not sticking.
      if (frictional)
        tangent.insert(tangent.end(), {p.tangent(j, 0), p.tangent(j, 1)});
      else
        tangent.insert(tangent.end(), {-p.normal(j, 1), p.normal(j, 0)});
      tangential_traction.push_back(frictional ? p.tangential_traction[j] : 0.0);
      slip.push_back(frictional ? p.slip[j] : nan);
      stick.push_back(frictional ? static_cast<std::int8_t>(p.stick[j]) : std::int8_t{0});
    }
    const auto lines = pair_segments(n, closed);
    for (Eigen::Index j = 0; j < lines.rows(); ++j)
      segments.insert(segments.end(), {first + lines(j, 0), first + lines(j, 1)});
    offsets.push_back(static_cast<std::int64_t>(node.size()));
    segment_offsets.push_back(static_cast<std::int64_t>(segments.size() / 2));
    slave_body.push_back(p.slave_body);
    slave_edge.push_back(p.slave_edge);
    master_body.push_back(p.master_body);
    master_edge.push_back(p.master_edge);
    enforcement.push_back(p.enforcement);
    friction.push_back(p.friction);
    theta.push_back(p.theta);
    force.push_back(p.force);
    resultant.insert(resultant.end(), {p.resultant.x(), p.resultant.y()});
    friction_coefficient.push_back(frictional ? p.friction_coefficient : 0.0);
    friction_bound.push_back(frictional ? p.friction_bound : 0.0);
    tangential_force.push_back(frictional ? p.tangential_force : 0.0);
  }
};

template <class T>
void write_pairs_of(hid_t g, const std::string& name, const std::vector<T>& data) {
  h5::write_dataset(g, name, data, {static_cast<hsize_t>(data.size() / 2), 2});
}

// ---- reading ------------------------------------------------------------------------------------------------

template <class T>
Eigen::Matrix<T, Eigen::Dynamic, 1> slice(const std::vector<T>& v, std::int64_t begin, std::int64_t end) {
  Eigen::Matrix<T, Eigen::Dynamic, 1> out(end - begin);
  for (std::int64_t j = begin; j < end; ++j) out[j - begin] = v[static_cast<size_t>(j)];
  return out;
}

Eigen::MatrixX2d slice2(const std::vector<double>& v, std::int64_t begin, std::int64_t end) {
  Eigen::MatrixX2d out(end - begin, 2);
  for (std::int64_t j = begin; j < end; ++j)
    out.row(j - begin) << v[static_cast<size_t>(2 * j)], v[static_cast<size_t>(2 * j + 1)];
  return out;
}

// A table of the contacts group with `rows` x `cols` entries (cols 0: one column), row-major.
template <class T>
std::vector<T> table(hid_t g, const std::string& name, std::int64_t rows, int cols) {
  std::vector<hsize_t> dims;
  std::vector<T> v = h5::read_dataset<T>(g, name, cols == 0 ? 1 : 2, dims);
  if (static_cast<std::int64_t>(dims[0]) != rows || (cols > 0 && dims[1] != static_cast<hsize_t>(cols)))
    throw std::runtime_error("dataset '" + h5::object_name(g) + "/" + name + "' has " + std::to_string(dims[0]) +
                             " rows, expected " + std::to_string(rows));
  return v;
}

std::vector<std::string> strings(hid_t g, const std::string& name, size_t count) {
  std::vector<std::string> v = h5::read_strings_dataset(g, name);
  if (v.size() != count)
    throw std::runtime_error("dataset '" + h5::object_name(g) + "/" + name + "' has " + std::to_string(v.size()) +
                             " entries for " + std::to_string(count) + " pairs");
  return v;
}

std::vector<PairField> read_tables(hid_t g, const std::vector<std::string>& names) {
  const size_t count = names.size();
  const auto offsets = table<std::int64_t>(g, "offsets", static_cast<std::int64_t>(count) + 1, 0);
  const std::int64_t n = offsets.back();
  bool rising = offsets[0] == 0;
  for (size_t p = 0; p < count; ++p) rising = rising && offsets[p] <= offsets[p + 1];
  if (!rising) throw std::runtime_error("dataset '" + h5::object_name(g) + "/offsets' does not increase from 0");
  const auto node = table<std::int64_t>(g, "node", n, 0);
  const auto position = table<double>(g, "position", n, 2), normal = table<double>(g, "normal", n, 2),
             tangent = table<double>(g, "tangent", n, 2);
  const auto arc_length = table<double>(g, "arc_length", n, 0), weight = table<double>(g, "weight", n, 0),
             gap = table<double>(g, "gap", n, 0), normal_gap = table<double>(g, "normal_gap", n, 0),
             pressure = table<double>(g, "pressure", n, 0), penetration = table<double>(g, "penetration", n, 0),
             traction = table<double>(g, "tangential_traction", n, 0), slip = table<double>(g, "slip", n, 0);
  const auto active = table<int>(g, "active", n, 0), status = table<int>(g, "status", n, 0),
             stick = table<int>(g, "stick", n, 0);
  const auto slave_body = strings(g, "slave_body", count), slave_edge = strings(g, "slave_edge", count),
             master_body = strings(g, "master_body", count), master_edge = strings(g, "master_edge", count),
             enforcement = strings(g, "enforcement", count), friction = strings(g, "friction", count);
  const auto P = static_cast<std::int64_t>(count);
  const auto theta = table<double>(g, "theta", P, 0), force = table<double>(g, "force", P, 0),
             resultant = table<double>(g, "resultant", P, 2), mu = table<double>(g, "friction_coefficient", P, 0),
             bound = table<double>(g, "friction_bound", P, 0), tforce = table<double>(g, "tangential_force", P, 0);
  std::vector<PairField> out(count);
  for (size_t p = 0; p < count; ++p) {
    PairField& f = out[p];
    const std::int64_t b = offsets[p], e = offsets[p + 1];
    f.name = names[p];
    f.slave_body = slave_body[p];
    f.slave_edge = slave_edge[p];
    f.master_body = master_body[p];
    f.master_edge = master_edge[p];
    f.enforcement = enforcement[p];
    f.theta = theta[p];
    f.force = force[p];
    f.resultant = Eigen::Vector2d(resultant[2 * p], resultant[2 * p + 1]);
    f.node = slice(node, b, e).cast<int>();
    f.position = slice2(position, b, e);
    f.normal = slice2(normal, b, e);
    f.arc_length = slice(arc_length, b, e);
    f.weight = slice(weight, b, e);
    f.gap = slice(gap, b, e);
    f.normal_gap = slice(normal_gap, b, e);
    f.pressure = slice(pressure, b, e);
    f.penetration = slice(penetration, b, e);
    f.active = slice(active, b, e);
    f.status = slice(status, b, e);
    f.friction = friction[p];
    if (f.friction != "none") {  // a frictionless pair's friction fields stay empty, as the solver leaves them
      f.friction_coefficient = mu[p];
      f.friction_bound = bound[p];
      f.tangential_force = tforce[p];
      f.tangent = slice2(tangent, b, e);
      f.tangential_traction = slice(traction, b, e);
      f.slip = slice(slip, b, e);
      f.stick = slice(stick, b, e);
    }
  }
  return out;
}

// Format version 2 and before: a group per pair, its scalars as attributes.
PairField read_pair_group(hid_t contacts, const std::string& name) {
  Handle g = h5::open_group(contacts, name);
  PairField p;
  p.name = name;
  p.slave_body = h5::read_string_attribute(g, "slave_body");
  p.slave_edge = h5::read_string_attribute(g, "slave_edge");
  p.master_body = h5::read_string_attribute(g, "master_body");
  p.master_edge = h5::read_string_attribute(g, "master_edge");
  p.enforcement = h5::read_string_attribute(g, "enforcement");
  p.theta = h5::read_attribute<double>(g, "theta");
  p.force = h5::read_attribute<double>(g, "force");
  if (h5::has_attribute(g, "resultant")) {
    const auto r = h5::read_attribute_array<double>(g, "resultant");
    if (r.size() == 2) p.resultant = Eigen::Vector2d(r[0], r[1]);
  }
  p.node = read_column<int>(g, "node");
  p.position = read_matrix<double>(g, "position", 2);
  p.normal = read_matrix<double>(g, "normal", 2);
  p.arc_length = read_column<double>(g, "arc_length");
  p.weight = read_column<double>(g, "weight");
  p.gap = read_column<double>(g, "gap");
  p.normal_gap = read_column<double>(g, "normal_gap");
  p.pressure = read_column<double>(g, "pressure");
  p.penetration = read_column<double>(g, "penetration");
  p.active = read_column<int>(g, "active");
  p.status = read_column<int>(g, "status");
  if (h5::has_attribute(g, "friction")) p.friction = h5::read_string_attribute(g, "friction");  // (older files: none)
  if (p.friction != "none") {
    p.friction_coefficient = h5::read_attribute<double>(g, "friction_coefficient");
    p.friction_bound = h5::read_attribute<double>(g, "friction_bound");
    p.tangential_force = h5::read_attribute<double>(g, "tangential_force");
    p.tangent = read_matrix<double>(g, "tangent", 2);
    p.tangential_traction = read_column<double>(g, "tangential_traction");
    p.slip = read_column<double>(g, "slip");
    p.stick = read_column<int>(g, "stick");
  }
  return p;
}

}  // namespace

void write_contact_tables(hid_t step, const Step& s, const std::string& where) {
  Tables t;
  for (const auto& p : s.pairs) {
    check_pair_rows(p, where);
    t.add(p, slave_is_closed(s, p));
  }
  Handle g = h5::create_group(step, "contacts");
  h5::write_vector(g, "offsets", t.offsets);
  h5::write_vector(g, "segment_offsets", t.segment_offsets);
  h5::write_strings_dataset(g, "slave_body", t.slave_body);
  h5::write_strings_dataset(g, "slave_edge", t.slave_edge);
  h5::write_strings_dataset(g, "master_body", t.master_body);
  h5::write_strings_dataset(g, "master_edge", t.master_edge);
  h5::write_strings_dataset(g, "enforcement", t.enforcement);
  h5::write_strings_dataset(g, "friction", t.friction);
  h5::write_vector(g, "theta", t.theta);
  h5::write_vector(g, "force", t.force);
  write_pairs_of(g, "resultant", t.resultant);
  h5::write_vector(g, "friction_coefficient", t.friction_coefficient);
  h5::write_vector(g, "friction_bound", t.friction_bound);
  h5::write_vector(g, "tangential_force", t.tangential_force);
  h5::write_vector(g, "pair", t.pair);
  h5::write_vector(g, "node", t.node);
  write_pairs_of(g, "position", t.position);
  write_pairs_of(g, "normal", t.normal);
  h5::write_vector(g, "arc_length", t.arc_length);
  h5::write_vector(g, "status", t.status);
  h5::write_vector(g, "weight", t.weight);
  h5::write_vector(g, "gap", t.gap);
  h5::write_vector(g, "normal_gap", t.normal_gap);
  h5::write_vector(g, "pressure", t.pressure);
  h5::write_vector(g, "penetration", t.penetration);
  h5::write_vector(g, "active", t.active);
  write_pairs_of(g, "tangent", t.tangent);
  h5::write_vector(g, "tangential_traction", t.tangential_traction);
  h5::write_vector(g, "slip", t.slip);
  h5::write_vector(g, "stick", t.stick);
  write_pairs_of(g, "segments", t.segments);
}

std::vector<PairField> read_contact_tables(hid_t contacts, const std::vector<std::string>& names, int format_version) {
  if (format_version >= 3) return read_tables(contacts, names);
  std::vector<PairField> out;
  for (const auto& name : names) out.push_back(read_pair_group(contacts, name));
  return out;
}

}  // namespace contact::io
