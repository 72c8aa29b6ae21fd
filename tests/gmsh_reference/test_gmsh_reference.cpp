// The MSH 4.1 reader (solver/mesh/gmsh_read.cpp, gmsh_surface.cpp) against Gmsh's own reading of the same files
// through its library: every physical surface has the same cells and every physical curve the same segments
// (compared by coordinates, so that neither numbering matters). Built only where libgmsh is installed
// (tests/CMakeLists.txt); a separate executable, since libgmsh loads OpenCASCADE.
#include "mesh/gmsh.hpp"

#include <gmsh.h>
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>

using namespace contact;

namespace {

using Segment = std::set<std::pair<double, double>>;  // unordered end points
using Cell = std::multiset<std::pair<double, double>>;

Segment segment(const std::pair<double, double>& a, const std::pair<double, double>& b) {
  Segment s;
  s.insert(a);
  s.insert(b);
  return s;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

class GmshReference : public ::testing::TestWithParam<std::string> {
 protected:
  static void SetUpTestSuite() {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
  }
  static void TearDownTestSuite() { gmsh::finalize(); }
};

}  // namespace

TEST_P(GmshReference, EveryPhysicalSurfaceAndCurveIsReadAsGmshReadsIt) {
  const std::string path = std::string(CONTACT_SOURCE_DIR) + "/api/examples/" + GetParam();
  gmsh::clear();
  gmsh::open(path);
  std::vector<std::size_t> tags;
  std::vector<double> xyz, parametric;
  gmsh::model::mesh::getNodes(tags, xyz, parametric);
  std::map<std::size_t, std::pair<double, double>> at;
  for (size_t k = 0; k < tags.size(); ++k) at[tags[k]] = {xyz[3 * k], xyz[3 * k + 1]};

  const mesh::gmsh::File file = mesh::gmsh::parse(read_text(path), 10'000'000);
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, 2);
  ASSERT_FALSE(groups.empty());
  std::map<std::string, std::set<Segment>> ours;  // physical curve -> its sides on all surfaces
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    std::multiset<Cell> expected;
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    for (int e : entities) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> element_tags, node_tags;
      gmsh::model::mesh::getElements(types, element_tags, node_tags, 2, e);
      for (size_t t = 0; t < types.size(); ++t) {
        const size_t per = types[t] == 2 ? 3 : 4;
        for (size_t k = 0; k < node_tags[t].size(); k += per) {
          Cell c;
          for (size_t j = 0; j < per; ++j) c.insert(at.at(node_tags[t][k + j]));
          expected.insert(c);
        }
      }
    }
    const auto s = mesh::gmsh::surface(file, name);
    ASSERT_TRUE(s.errors.empty()) << name << ": " << s.errors[0];
    std::multiset<Cell> got;
    for (const auto& cell : s.mesh.cells) {
      Cell c;
      for (int n : cell) c.insert({s.mesh.nodes[static_cast<size_t>(n)].x(), s.mesh.nodes[static_cast<size_t>(n)].y()});
      got.insert(c);
    }
    EXPECT_EQ(got.size(), expected.size()) << name;
    EXPECT_TRUE(got == expected) << name;
    for (const auto& [edge, refs] : s.mesh.edge_sets)
      for (const auto& e : refs) {
        const auto n = s.mesh.edge_nodes(e);
        ours[edge].insert(segment({s.mesh.nodes[static_cast<size_t>(n[0])].x(), s.mesh.nodes[static_cast<size_t>(n[0])].y()},
                                  {s.mesh.nodes[static_cast<size_t>(n[1])].x(), s.mesh.nodes[static_cast<size_t>(n[1])].y()}));
      }
  }
  gmsh::model::getPhysicalGroups(groups, 1);
  ASSERT_FALSE(groups.empty());
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    std::set<Segment> expected;
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    for (int e : entities) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> element_tags, node_tags;
      gmsh::model::mesh::getElements(types, element_tags, node_tags, 1, e);
      for (size_t t = 0; t < types.size(); ++t)
        for (size_t k = 0; k + 1 < node_tags[t].size(); k += 2) expected.insert(segment(at.at(node_tags[t][k]), at.at(node_tags[t][k + 1])));
    }
    EXPECT_EQ(ours[name].size(), expected.size()) << name;
    EXPECT_TRUE(ours[name] == expected) << name;  // every curve of the examples lies on some surface's boundary
  }
}

INSTANTIATE_TEST_SUITE_P(Examples, GmshReference,
                         ::testing::Values("flat_patch_gmsh.msh", "punch_rounded_gmsh.msh", "hertz_cylinder_gmsh.msh"),
                         [](const auto& info) { return info.param.substr(0, info.param.find('.')); });
