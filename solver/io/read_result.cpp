// read_result: HDF5 result file -> ResultFile (the inverse of write_result, for tests and tools).
#include "contact/result_file.hpp"

#include "contact_tables.hpp"
#include "collapse_group.hpp"
#include "h5.hpp"
#include "h5_eigen.hpp"
#include "result_layout.hpp"

#include <stdexcept>
#include <type_traits>

namespace contact::io {

namespace {

using h5::Handle;

using h5::read_column;
using h5::read_matrix;

// A dataset of any rank <= 2 as a matrix with one column per component.
Eigen::MatrixXd read_components(hid_t loc, const std::string& name) {
  const auto shape = h5::dataset_shape(loc, name);
  if (shape.size() == 1) return read_column<double>(loc, name);
  return read_matrix<double>(loc, name);
}

// One attribute of result_layout.hpp's lists into its member. An optional one a file written before it existed lacks
// leaves the member as it is; a required one missing throws (naming it).
struct AttributeReader {
  hid_t obj;
  bool absent(const AttributeColumn& a) const { return a.optional && !h5::has_attribute(obj, a.name); }
  void operator()(const AttributeColumn& a, std::string& v) const {
    if (!absent(a)) v = h5::read_string_attribute(obj, a.name);
  }
  void operator()(const AttributeColumn& a, bool& v) const {
    if (!absent(a)) v = h5::read_attribute<std::int32_t>(obj, a.name) != 0;
  }
  void operator()(const AttributeColumn& a, int& v) const {
    if (!absent(a)) v = h5::read_attribute<std::int32_t>(obj, a.name);
  }
  void operator()(const AttributeColumn& a, std::int64_t& v) const {
    if (!absent(a)) v = h5::read_attribute<std::int64_t>(obj, a.name);
  }
  void operator()(const AttributeColumn& a, double& v) const {
    if (!absent(a)) v = h5::read_attribute<double>(obj, a.name);
  }
};

void read_root(hid_t file, ResultFile& r) {
  if (!h5::has_attribute(file, "format"))
    throw std::runtime_error(std::string("not a result file: the root has no 'format' attribute (expected '") +
                             kFormatName + "')");
  r.format = h5::read_string_attribute(file, "format");
  if (r.format != kFormatName)
    throw std::runtime_error("not a result file: format is '" + r.format + "', expected '" + kFormatName + "'");
  r.format_version = h5::read_attribute<std::int32_t>(file, "format_version");
  if (r.format_version > kFormatVersion)
    throw std::runtime_error("format_version " + std::to_string(r.format_version) + " is newer than this reader's " +
                             std::to_string(kFormatVersion));
  root_attributes(r, AttributeReader{file});
}

void read_input_and_provenance(hid_t file, ResultFile& r) {
  Handle input = h5::open_group(file, "input");
  r.job_json = h5::read_string_dataset(input, "job");
  r.normalized_json = h5::read_string_dataset(input, "normalized");

  if (h5::has_link(file, "warnings")) {  // (absent in files written before the model checks)
    Handle warnings = h5::open_group(file, "warnings");
    const auto pointers = h5::read_strings_dataset(warnings, "pointer");
    const auto messages = h5::read_strings_dataset(warnings, "message");
    if (pointers.size() != messages.size())
      throw std::runtime_error("/warnings: " + std::to_string(pointers.size()) + " pointers for " +
                               std::to_string(messages.size()) + " messages");
    for (size_t k = 0; k < pointers.size(); ++k) r.warnings.push_back({pointers[k], messages[k]});
  }

  read_collapse(file, r.collapse);

  Handle prov = h5::open_group(file, "provenance");
  Provenance& p = r.provenance;
  provenance_attributes(p, AttributeReader{prov});
  p.pair_names = h5::read_strings_dataset(prov, "pair_names");
  p.theta = h5::read_vector<double>(prov, "theta");
}

// One dataset of a history table (result_layout.hpp) into its member; an optional one older files lack is left
// empty.
struct ColumnReader {
  hid_t group;
  Eigen::Index bodies, pairs;
  bool absent(const HistoryColumn& c) const { return c.optional && !h5::has_link(group, c.name); }
  void operator()(const HistoryColumn& c, std::vector<int>& v) const {
    if (absent(c)) return;
    if (c.stored == HistoryColumn::Stored::int8) {
      const auto stored = h5::read_vector<std::int8_t>(group, c.name);
      v.assign(stored.begin(), stored.end());
    } else {
      v = h5::read_vector<int>(group, c.name);
    }
  }
  void operator()(const HistoryColumn& c, std::vector<double>& v) const {
    if (!absent(c)) v = h5::read_vector<double>(group, c.name);
  }
  void operator()(const HistoryColumn& c, std::vector<std::string>& v) const {
    if (!absent(c)) v = h5::read_strings_dataset(group, c.name);
  }
  template <class T>
  void operator()(const HistoryColumn& c, Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>& m) const {
    if (!absent(c)) m = read_matrix<T>(group, c.name, c.across == HistoryColumn::Across::bodies ? bodies : pairs);
  }
};

template <class History>
void read_table(hid_t history, const char* name, History& h) {
  Handle g = h5::open_group(history, name);
  h.body_names = h5::read_strings_attribute(g, "body_names");
  h.pair_names = h5::read_strings_attribute(g, "pair_names");
  const ColumnReader reader{g, static_cast<Eigen::Index>(h.body_names.size()),
                            static_cast<Eigen::Index>(h.pair_names.size())};
  if constexpr (std::is_same_v<History, IterationHistory>)
    iteration_columns(h, reader);
  else
    step_columns(h, reader);
}

void read_history(hid_t file, ResultFile& r) {
  Handle history = h5::open_group(file, "history");
  read_table(history, "iterations", r.history);
  read_table(history, "steps", r.step_history);
}

BodyField read_body(hid_t bodies, const std::string& name) {
  Handle g = h5::open_group(bodies, name);
  BodyField b;
  b.name = name;
  const Eigen::MatrixXd points = read_matrix<double>(g, "points", 2);
  // `cells` (a triangle's last column -1); files written before triangles existed have only `quads`.
  const Eigen::MatrixXi cells = read_matrix<int>(g, h5::has_link(g, "cells") ? "cells" : "quads", 4);
  for (Eigen::Index i = 0; i < points.rows(); ++i) b.mesh.nodes.emplace_back(points(i, 0), points(i, 1));
  for (Eigen::Index e = 0; e < cells.rows(); ++e) {
    if (cells(e, 3) < 0)
      b.mesh.cells.emplace_back(cells(e, 0), cells(e, 1), cells(e, 2));
    else
      b.mesh.cells.emplace_back(cells(e, 0), cells(e, 1), cells(e, 2), cells(e, 3));
  }
  b.mesh.level = h5::read_vector<int>(g, "level");
  body_fields(b, [&](const BodyFieldColumn& f, auto& v) {
    if (f.optional && !h5::has_link(g, f.name)) return;
    if constexpr (std::decay_t<decltype(v)>::ColsAtCompileTime == 1)
      v = read_column<double>(g, f.name);
    else
      v = read_matrix<double>(g, f.name, f.components);
  });
  if (h5::has_attribute(g, "reaction_total")) {  // since the resultants (older files: absent)
    const auto t = h5::read_attribute_array<double>(g, "reaction_total");
    if (t.size() == 2) b.reaction_total = Eigen::Vector2d(t[0], t[1]);
  }
  if (h5::has_link(g, "support_reactions")) {
    const auto names = h5::read_strings_attribute(g, "support_names");
    const Eigen::MatrixXd sums = read_matrix<double>(g, "support_reactions", 2);
    for (size_t i = 0; i < names.size() && static_cast<Eigen::Index>(i) < sums.rows(); ++i)
      b.support_reactions.push_back({names[i], sums.row(static_cast<Eigen::Index>(i)).transpose()});
  }
  if (h5::has_attribute(g, "free_motions")) {
    b.free_motions = h5::read_strings_attribute(g, "free_motions");
    const auto c = h5::read_attribute_array<double>(g, "rigid_center");
    const auto m = h5::read_attribute_array<double>(g, "rigid_motion");
    if (c.size() == 2) b.rigid_center = Eigen::Vector2d(c[0], c[1]);
    if (m.size() == 3) b.rigid_motion = Eigen::Vector3d(m[0], m[1], m[2]);
  }
  return b;
}

void read_steps(hid_t file, ResultFile& r) {
  Handle steps = h5::open_group(file, "steps");
  const int count = h5::read_attribute<std::int32_t>(steps, "count");
  for (int k = 0; k < count; ++k) {
    Handle g = h5::open_group(steps, std::to_string(k));
    Step s;
    s.index = h5::has_attribute(g, "step") ? h5::read_attribute<std::int32_t>(g, "step") : k;  // its history row
    s.iteration = h5::read_attribute<std::int32_t>(g, "iteration");
    s.load_factor = h5::read_attribute<double>(g, "load_factor");
    if (h5::has_attribute(g, "multiplier")) s.multiplier = h5::read_attribute<double>(g, "multiplier");
    s.converged = !h5::has_attribute(g, "converged") || h5::read_attribute<std::int8_t>(g, "converged") != 0;
    Handle bodies = h5::open_group(g, "bodies");
    for (const auto& name : h5::read_strings_attribute(g, "body_names")) s.bodies.push_back(read_body(bodies, name));
    Handle contacts = h5::open_group(g, "contacts");
    s.pairs = read_contact_tables(contacts, h5::read_strings_attribute(g, "pair_names"), r.format_version);
    r.steps.push_back(std::move(s));
  }
}

void read_vtkhdf(hid_t file, ResultFile& r) {
  if (!h5::has_link(file, "VTKHDF")) return;
  Handle v = h5::open_group(file, "VTKHDF");
  VtkHdf& out = r.vtkhdf;
  out.present = true;
  out.version = h5::read_attribute_array<std::int64_t>(v, "Version");
  out.type = h5::read_string_attribute(v, "Type");
  const h5::StringTypeInfo info = h5::string_attribute_type(v, "Type");
  out.type_storage.fixed_length = info.is_string && !info.variable_length;
  out.type_storage.size = info.size;
  out.type_storage.padding = info.padding == H5T_STR_NULLPAD    ? "nullpad"
                             : info.padding == H5T_STR_NULLTERM ? "nullterm"
                             : info.padding == H5T_STR_SPACEPAD ? "spacepad"
                                                                : "";
  out.number_of_points = h5::read_vector<std::int64_t>(v, "NumberOfPoints");
  out.number_of_cells = h5::read_vector<std::int64_t>(v, "NumberOfCells");
  out.number_of_connectivity_ids = h5::read_vector<std::int64_t>(v, "NumberOfConnectivityIds");
  out.points = read_matrix<double>(v, "Points", 3);
  out.connectivity = h5::read_vector<std::int64_t>(v, "Connectivity");
  out.offsets = h5::read_vector<std::int64_t>(v, "Offsets");
  out.types = h5::read_vector<std::uint8_t>(v, "Types");
  for (const char* group : {"PointData", "CellData"}) {
    if (!h5::has_link(v, group)) continue;
    Handle g = h5::open_group(v, group);
    auto& arrays = std::string(group) == "PointData" ? out.point_data : out.cell_data;
    for (const auto& name : h5::link_names(g)) arrays[name] = read_components(g, name);
  }
}

}  // namespace

ResultFile read_result(const std::string& path) {
  try {
    h5::QuietErrors quiet;
    Handle file = h5::open_file(path);
    ResultFile r;
    read_root(file, r);
    read_input_and_provenance(file, r);
    read_history(file, r);
    read_steps(file, r);
    read_vtkhdf(file, r);
    return r;
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read result file '" + path + "': " + e.what());
  }
}

}  // namespace contact::io
