// The result file's tables, declared once (solver/io/result_layout.hpp): what the format document says, name, shape
// and type, and what is written is what is read.
#include "contact/job.hpp"
#include "contact/result_file.hpp"
#include "contact/solve.hpp"
#include "io/result_layout.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <string>
#include <type_traits>

// ---- the history tables: declared once (io/result_layout.hpp), documented once (docs/results-format.md) ----

namespace {

// A history table as a set of "name shape type" lines, e.g. "force (I, P) float64".
using ColumnSet = std::set<std::string>;

template <class Walk>
ColumnSet declared_columns(Walk walk, const char* rows) {
  ColumnSet out;
  walk([&](const contact::io::HistoryColumn& c, const auto&) {
    using A = contact::io::HistoryColumn::Across;
    using S = contact::io::HistoryColumn::Stored;
    const std::string shape = std::string("(") + rows +
                              (c.across == A::none     ? ",)"
                               : c.across == A::bodies ? ", B)"
                                                       : ", P)");
    const std::string type = c.stored == S::int32     ? "int32"
                             : c.stored == S::int8    ? "int8"
                             : c.stored == S::float64 ? "float64"
                                                      : "str";
    out.insert(std::string(c.name) + " " + shape + " " + type);
  });
  return out;
}

// The dataset tables of docs/results-format.md from the line that starts with `from` to the next heading (or the
// line that starts with `until`): each row's names (one or more, in backticks, in its first cell) with its shape
// and type (its second cell).
ColumnSet documented_columns(const std::string& from, const std::string& until = "### ") {
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/docs/results-format.md");
  std::string line;
  bool inside = false;
  ColumnSet out;
  while (std::getline(in, line)) {
    if (inside && (line.rfind("### ", 0) == 0 || line.rfind(until, 0) == 0)) break;
    if (!inside) {
      inside = line.rfind(from, 0) == 0;
      continue;
    }
    if (line.rfind("| `", 0) != 0) continue;
    const size_t first_end = line.find(" | ", 2);
    const size_t second_end = line.find(" | ", first_end + 3);
    if (first_end == std::string::npos || second_end == std::string::npos) continue;
    const std::string names = line.substr(2, first_end - 2);
    const std::string shape_type = line.substr(first_end + 3, second_end - first_end - 3);
    static const std::regex name("`([a-z_]+)`");
    for (std::sregex_iterator it(names.begin(), names.end(), name), end; it != end; ++it)
      out.insert((*it)[1].str() + " " + shape_type);
  }
  return out;
}

}  // namespace

TEST(ResultLayout, TheIterationHistoryIsTheDocumentsTableNameShapeAndType) {
  contact::io::IterationHistory h;
  const ColumnSet declared = declared_columns([&](auto visit) { contact::io::iteration_columns(h, visit); }, "I");
  const ColumnSet documented = documented_columns("### `/history/iterations`");
  EXPECT_EQ(declared.size(), 20u);
  EXPECT_EQ(declared, documented);
}

TEST(ResultLayout, TheStepHistoryIsTheDocumentsTableNameShapeAndType) {
  contact::io::StepHistory h;
  const ColumnSet declared = declared_columns([&](auto visit) { contact::io::step_columns(h, visit); }, "S");
  const ColumnSet documented = documented_columns("### `/history/steps`");
  EXPECT_EQ(declared.size(), 11u);
  EXPECT_EQ(declared, documented);
}

TEST(ResultLayout, TheContactTablesAreTheDocumentsTablesNameShapeAndType) {
  contact::io::ContactTables t;
  ColumnSet declared;
  contact::io::contact_columns(t, [&](const contact::io::ContactColumn& c, const auto& member) {
    using R = contact::io::ContactColumn::Rows;
    using T = typename std::decay_t<decltype(member)>::value_type;
    const std::string rows = c.rows == R::pair_offsets ? "P+1"
                             : c.rows == R::pairs      ? "P"
                             : c.rows == R::nodes      ? "N"
                                                       : "L";
    const std::string type = std::is_same_v<T, std::string>    ? "str"
                             : std::is_same_v<T, double>       ? "float64"
                             : std::is_same_v<T, std::int64_t> ? "int64"
                             : std::is_same_v<T, std::int32_t> ? "int32"
                                                               : "int8";
    declared.insert(std::string(c.name) + " (" + rows + (c.width == 2 ? ", 2)" : ",)") + " " + type);
  });
  const ColumnSet documented = documented_columns("`/steps/<k>/contacts/` holds", "A version 2 file");
  EXPECT_EQ(declared.size(), 36u);
  EXPECT_EQ(declared, documented);
}

// A body's fields are declared once (body_fields); the document's body table lists them with their shapes, and
// besides them only what write_body makes from the mesh and the fields (named here: a dataset the writer adds
// must be one or the other).
TEST(ResultLayout, TheBodyFieldsAreTheDocumentsBodyTableNameShapeAndType) {
  contact::BodyField b;
  ColumnSet declared;
  std::set<std::string> names;
  contact::io::body_fields(b, [&](const contact::io::BodyFieldColumn& f, const auto&) {
    const std::string rows = f.per == contact::io::BodyFieldColumn::Per::node ? "n" : "m";
    declared.insert(std::string(f.name) + " (" + rows +
                    (f.components == 1 ? ",)" : ", " + std::to_string(f.components) + ")") + " float64");
    names.insert(f.name);
  });
  const ColumnSet documented = documented_columns("`/steps/<k>/bodies/<body>/`:", "`/steps/<k>/contacts/` holds");
  const std::set<std::string> from_the_mesh = {"points",           "cells", "cell_types",         "quads",
                                               "xdmf_topology",    "level", "stress_cell_tensor", "stress_node_tensor",
                                               "support_reactions"};
  EXPECT_EQ(declared.size(), 6u);
  for (const auto& line : declared) EXPECT_EQ(documented.count(line), 1u) << line << " is not in the document";
  for (const auto& line : documented) {
    const std::string name = line.substr(0, line.find(' '));
    EXPECT_TRUE(names.count(name) || from_the_mesh.count(name)) << name << " is documented but neither declared "
                                                                << "(body_fields) nor made by write_body";
  }
}

// The root's attributes and /provenance's are declared once (root_attributes, provenance_attributes): the root's are
// the document's table, name and type; every attribute of /provenance is named in its section.
TEST(ResultLayout, TheRootAndProvenanceAttributesAreTheDocuments) {
  auto type_of = [](const contact::io::AttributeColumn& a) {
    using S = contact::io::AttributeColumn::Stored;
    return a.stored == S::text ? "str" : a.stored == S::int32 ? "int32" : a.stored == S::int64 ? "int64" : "float64";
  };
  contact::io::ResultFile r;
  ColumnSet declared;
  contact::io::root_attributes(r, [&](const contact::io::AttributeColumn& a, const auto&) {
    declared.insert(std::string(a.name) + " " + type_of(a));
  });
  EXPECT_EQ(declared.size(), 12u);
  EXPECT_EQ(declared, documented_columns("### Root attributes"));

  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/docs/results-format.md");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t from = text.find("### `/provenance`"), to = text.find("\n### ", from + 1);
  ASSERT_NE(from, std::string::npos);
  const std::string section = text.substr(from, to - from);
  int count = 0;
  contact::io::provenance_attributes(r.provenance, [&](const contact::io::AttributeColumn& a, const auto&) {
    EXPECT_NE(section.find(std::string("`") + a.name + "`"), std::string::npos) << a.name << " is not documented";
    ++count;
  });
  EXPECT_EQ(count, 12);
}

TEST(ResultLayout, TheHistoryTablesReadBackAsWritten) {
  // Written by the one table and read by it: every column comes back (two load steps, Coulomb on one pair).
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/tests/data/result_format_v2.json");
  const auto parsed = contact::job::parse(nlohmann::json::parse(in));
  ASSERT_TRUE(parsed.ok()) << contact::job::format_errors(parsed.errors);
  contact::Observer quiet;
  contact::CancelToken cancel;
  const contact::Result result = contact::solve(*parsed.problem, quiet, cancel);
  ASSERT_TRUE(result.converged) << result.message;
  const std::string path = (std::filesystem::temp_directory_path() / "result_tables_roundtrip.hdf").string();
  contact::io::write_result(path, *parsed.problem, result);
  const contact::io::ResultFile file = contact::io::read_result(path);
  std::filesystem::remove(path);
  ASSERT_EQ(file.history.iteration.size(), result.history.size());
  for (size_t i = 0; i < result.history.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    EXPECT_EQ(file.history.iteration[i], result.history[i].iteration);
    EXPECT_EQ(file.history.measure[i], contact::to_string(result.history[i].measure));
    EXPECT_EQ(file.history.complementarity[i], result.history[i].complementarity);
    EXPECT_EQ(file.history.force(row, 1), result.history[i].pairs[1].force);
    EXPECT_EQ(file.history.changed_nodes(row, 0), result.history[i].pairs[0].changed_nodes);
    EXPECT_EQ(file.history.dofs(row, 1), result.history[i].bodies[1].dofs);
  }
  ASSERT_EQ(file.step_history.step.size(), 2u);
  EXPECT_EQ(file.step_history.converged, (std::vector<int>{1, 1}));
  EXPECT_EQ(file.step_history.load_factor.back(), result.steps.back().load_factor);
  double tangential = 0.0;
  for (Eigen::Index p = 0; p < file.step_history.tangential_force.cols(); ++p)
    tangential += std::abs(file.step_history.tangential_force(1, p));
  EXPECT_GT(tangential, 0.0) << "the Coulomb pair's tangential force";
  EXPECT_EQ(file.step_history.dofs.cols(), static_cast<Eigen::Index>(parsed.problem->bodies.size()));
}
