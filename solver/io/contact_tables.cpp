// contact_tables: a step's contact pairs as tables in the result file (contact_tables.hpp, docs/results-format.md).
#include "contact_tables.hpp"

#include "h5.hpp"
#include "h5_eigen.hpp"
#include "result_layout.hpp"
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

// Appends pair p to the tables of its step (result_layout.hpp).
void add_pair(ContactTables& t, const PairField& p, bool closed) {
  const Eigen::Index n = p.position.rows();
  const auto first = static_cast<std::int64_t>(t.node.size());
  const bool frictional = p.friction != "none";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Eigen::Index j = 0; j < n; ++j) {
    t.node.push_back(p.node[j]);
    t.pair.push_back(static_cast<std::int32_t>(t.offsets.size() - 1));
    t.position.insert(t.position.end(), {p.position(j, 0), p.position(j, 1)});
    t.normal.insert(t.normal.end(), {p.normal(j, 0), p.normal(j, 1)});
    t.arc_length.push_back(p.arc_length[j]);
    t.weight.push_back(p.weight[j]);
    t.gap.push_back(p.gap[j]);
    t.normal_gap.push_back(p.normal_gap[j]);
    t.pressure.push_back(p.pressure[j]);
    t.penetration.push_back(p.penetration[j]);
    t.active.push_back(static_cast<std::int8_t>(p.active[j]));
    t.status.push_back(static_cast<std::int8_t>(p.status[j]));
    // A frictionless pair's rows: its tangent (the normal turned a quarter anticlockwise), no traction, no slip
    // measured (NaN), not sticking.
    if (frictional)
      t.tangent.insert(t.tangent.end(), {p.tangent(j, 0), p.tangent(j, 1)});
    else
      t.tangent.insert(t.tangent.end(), {-p.normal(j, 1), p.normal(j, 0)});
    t.tangential_traction.push_back(frictional ? p.tangential_traction[j] : 0.0);
    t.slip.push_back(frictional ? p.slip[j] : nan);
    t.stick.push_back(frictional ? static_cast<std::int8_t>(p.stick[j]) : std::int8_t{0});
  }
  const auto lines = pair_segments(n, closed);
  for (Eigen::Index j = 0; j < lines.rows(); ++j)
    t.segments.insert(t.segments.end(), {first + lines(j, 0), first + lines(j, 1)});
  t.offsets.push_back(static_cast<std::int64_t>(t.node.size()));
  t.segment_offsets.push_back(static_cast<std::int64_t>(t.segments.size() / 2));
  t.slave_body.push_back(p.slave_body);
  t.slave_edge.push_back(p.slave_edge);
  t.master_body.push_back(p.master_body);
  t.master_edge.push_back(p.master_edge);
  t.enforcement.push_back(p.enforcement);
  t.friction.push_back(p.friction);
  t.theta.push_back(p.theta);
  t.force.push_back(p.force);
  t.resultant.insert(t.resultant.end(), {p.resultant.x(), p.resultant.y()});
  t.friction_coefficient.push_back(frictional ? p.friction_coefficient : 0.0);
  t.friction_bound.push_back(frictional ? p.friction_bound : 0.0);
  t.tangential_force.push_back(frictional ? p.tangential_force : 0.0);
  t.centre_of_pressure.push_back(p.joint.centre_of_pressure);
  t.eccentricity.push_back(p.joint.eccentricity);
  t.open_fraction.push_back(p.joint.open_fraction);
  t.slip_fraction.push_back(p.joint.slip_fraction);
  t.friction_utilisation.push_back(p.joint.friction_utilisation);
}

// One dataset of the contact tables (result_layout.hpp): a text per pair, or values in one or two columns.
struct TableWriter {
  hid_t group;
  void operator()(const ContactColumn& c, const std::vector<std::string>& v) const {
    h5::write_strings_dataset(group, c.name, v);
  }
  template <class T>
  void operator()(const ContactColumn& c, const std::vector<T>& v) const {
    if (c.width == 2)
      h5::write_dataset(group, c.name, v, {static_cast<hsize_t>(v.size() / 2), 2});
    else
      h5::write_vector(group, c.name, v);
  }
};

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

// One dataset of the contact tables into its member, its rows checked (result_layout.hpp).
struct TableReader {
  hid_t group;
  std::int64_t pairs, nodes, segments;
  std::int64_t rows(const ContactColumn& c) const {
    using R = ContactColumn::Rows;
    return c.rows == R::pair_offsets ? pairs + 1 : c.rows == R::pairs ? pairs : c.rows == R::nodes ? nodes : segments;
  }
  void operator()(const ContactColumn& c, std::vector<std::string>& v) const {
    v = strings(group, c.name, static_cast<size_t>(pairs));
  }
  template <class T>
  void operator()(const ContactColumn& c, std::vector<T>& v) const {
    if (c.optional && !h5::has_link(group, c.name)) return;
    v = table<T>(group, c.name, rows(c), c.width == 2 ? 2 : 0);
  }
};

// The offsets of one kind of row (nodes or segments): from 0, never decreasing; their last is the row count.
std::int64_t checked_offsets(hid_t g, const char* name, std::int64_t pairs) {
  const auto offsets = table<std::int64_t>(g, name, pairs + 1, 0);
  bool rising = offsets[0] == 0;
  for (std::int64_t p = 0; p < pairs; ++p)
    rising = rising && offsets[static_cast<size_t>(p)] <= offsets[static_cast<size_t>(p + 1)];
  if (!rising) throw std::runtime_error("dataset '" + h5::object_name(g) + "/" + name + "' does not increase from 0");
  return offsets.back();
}

std::vector<PairField> read_tables(hid_t g, const std::vector<std::string>& names) {
  const size_t count = names.size();
  const auto P = static_cast<std::int64_t>(count);
  ContactTables t;
  contact_columns(t, TableReader{g, P, checked_offsets(g, "offsets", P), checked_offsets(g, "segment_offsets", P)});
  std::vector<PairField> out(count);
  for (size_t p = 0; p < count; ++p) {
    PairField& f = out[p];
    const std::int64_t b = t.offsets[p], e = t.offsets[p + 1];
    f.name = names[p];
    f.slave_body = t.slave_body[p];
    f.slave_edge = t.slave_edge[p];
    f.master_body = t.master_body[p];
    f.master_edge = t.master_edge[p];
    f.enforcement = t.enforcement[p];
    f.theta = t.theta[p];
    f.force = t.force[p];
    f.resultant = Eigen::Vector2d(t.resultant[2 * p], t.resultant[2 * p + 1]);
    f.node = slice(t.node, b, e).cast<int>();
    f.position = slice2(t.position, b, e);
    f.normal = slice2(t.normal, b, e);
    f.arc_length = slice(t.arc_length, b, e);
    f.weight = slice(t.weight, b, e);
    f.gap = slice(t.gap, b, e);
    f.normal_gap = slice(t.normal_gap, b, e);
    f.pressure = slice(t.pressure, b, e);
    f.penetration = slice(t.penetration, b, e);
    f.active = slice(t.active, b, e).cast<int>();
    f.status = slice(t.status, b, e).cast<int>();
    f.friction = t.friction[p];
    if (f.friction != "none") {  // a frictionless pair's friction fields stay empty, as the solver leaves them
      f.friction_coefficient = t.friction_coefficient[p];
      f.friction_bound = t.friction_bound[p];
      f.tangential_force = t.tangential_force[p];
      f.tangent = slice2(t.tangent, b, e);
      f.tangential_traction = slice(t.tangential_traction, b, e);
      f.slip = slice(t.slip, b, e);
      f.stick = slice(t.stick, b, e).cast<int>();
    }
    // The joint results as written; from the fields where a file written before them lacks them.
    if (t.centre_of_pressure.size() == count)
      f.joint = {t.centre_of_pressure[p], t.eccentricity[p], t.open_fraction[p], t.slip_fraction[p],
                 t.friction_utilisation[p]};
    else
      f.joint = joint_results(f);
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
  p.joint = joint_results(p);  // (version 2 had none: from the fields)
  return p;
}

}  // namespace

void write_contact_tables(hid_t step, const Step& s, const std::string& where) {
  ContactTables t;
  for (const auto& p : s.pairs) {
    check_pair_rows(p, where);
    add_pair(t, p, slave_is_closed(s, p));
  }
  Handle g = h5::create_group(step, "contacts");
  contact_columns(t, TableWriter{g});
}

std::vector<PairField> read_contact_tables(hid_t contacts, const std::vector<std::string>& names, int format_version) {
  if (format_version >= 3) return read_tables(contacts, names);
  std::vector<PairField> out;
  for (const auto& name : names) out.push_back(read_pair_group(contacts, name));
  return out;
}

}  // namespace contact::io
