// gmsh::parse: MSH 4.1 ASCII text -> gmsh::File (the format: gmsh.info/doc/texinfo/gmsh.html#MSH-file-format).
//
// Sections read: $MeshFormat, $PhysicalNames, $Entities, $Nodes, $Elements. Others ($Periodic,
// $NodeData, ...) are skipped, as the format asks of readers; $PartitionedEntities is refused (a partitioned
// mesh numbers its entities differently). Counts in section headers are never trusted for allocation: vectors
// grow with what is actually read, so a header claiming 10^12 nodes costs nothing.
#include "gmsh.hpp"

#include <charconv>
#include <cmath>
#include <sstream>
#include <string_view>

namespace contact::mesh::gmsh {

namespace {

// Whitespace-separated tokens with the line they are on.
class Lexer {
 public:
  explicit Lexer(const std::string& text) : text_(text) {}

  bool at_end() {
    skip_space();
    return pos_ >= text_.size();
  }
  int line() const { return line_; }

  std::string_view token(const char* what) {
    skip_space();
    if (pos_ >= text_.size()) fail(std::string("the file ends where ") + what + " was expected");
    const size_t start = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
    return std::string_view(text_).substr(start, pos_ - start);
  }

  // The tokens of the current line from the next one on (the rest of the line).
  std::vector<std::string_view> rest_of_line() {
    std::vector<std::string_view> out;
    while (true) {
      while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\r')) ++pos_;
      if (pos_ >= text_.size() || text_[pos_] == '\n') break;
      const size_t start = pos_;
      while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
      out.push_back(std::string_view(text_).substr(start, pos_ - start));
    }
    return out;
  }

  // The next line's tokens (skipping empty lines).
  std::vector<std::string_view> next_line(const char* what) {
    skip_space();
    if (pos_ >= text_.size()) fail(std::string("the file ends where ") + what + " was expected");
    return rest_of_line();
  }

  // A quoted string on the current line ("..."), for physical names.
  std::string quoted(const char* what) {
    skip_space();
    if (pos_ >= text_.size() || text_[pos_] != '"') fail(std::string("expected ") + what + " in double quotes");
    const size_t end = text_.find('"', pos_ + 1);
    const size_t newline = text_.find('\n', pos_ + 1);
    if (end == std::string::npos || (newline != std::string::npos && newline < end))
      fail(std::string(what) + " has no closing double quote on its line");
    std::string out = text_.substr(pos_ + 1, end - pos_ - 1);
    pos_ = end + 1;
    return out;
  }

  // Skips to the line after the one holding `end_marker` (an unknown section).
  void skip_section(const std::string& end_marker) {
    while (!at_end())
      if (token(end_marker.c_str()) == end_marker) return;
    fail("the file ends inside a section: " + end_marker + " is missing");
  }

  [[noreturn]] void fail(const std::string& message) const {
    throw ParseError("line " + std::to_string(line_) + ": " + message);
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
  void skip_space() {
    while (pos_ < text_.size() && is_space(text_[pos_])) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  const std::string& text_;
  size_t pos_ = 0;
  int line_ = 1;
};

template <class T>
T integer(Lexer& in, std::string_view token, const char* what) {
  T value{};
  const auto r = std::from_chars(token.data(), token.data() + token.size(), value);
  if (r.ec != std::errc() || r.ptr != token.data() + token.size())
    in.fail(std::string(what) + " must be an integer, got '" + std::string(token.substr(0, 40)) + "'");
  return value;
}

template <class T>
T integer(Lexer& in, const char* what) {
  return integer<T>(in, in.token(what), what);
}

double real(Lexer& in, const char* what) {
  const std::string_view token = in.token(what);
  double value = 0;
  const auto r = std::from_chars(token.data(), token.data() + token.size(), value);
  if (r.ec != std::errc() || r.ptr != token.data() + token.size() || !std::isfinite(value))
    in.fail(std::string(what) + " must be a finite number, got '" + std::string(token.substr(0, 40)) + "'");
  return value;
}

void expect(Lexer& in, const char* marker) {
  const std::string_view t = in.token(marker);
  if (t != marker) in.fail(std::string("expected ") + marker + ", got '" + std::string(t.substr(0, 40)) + "'");
}

void read_format(Lexer& in) {
  const std::string_view version = in.token("the format version");
  if (version != "4.1") {
    const std::string v(version.substr(0, 20));
    in.fail("MSH format version " + v +
            " is not supported: this solver reads MSH 4.1 (Gmsh's default since 4.1; convert with: gmsh "
            "old.msh -save -format msh41 -o new.msh)");
  }
  const int file_type = integer<int>(in, "the file type");
  integer<int>(in, "the data size");
  if (file_type != 0)
    in.fail(
        "binary MSH files are not supported: save the mesh as ASCII (Mesh.Binary = 0, the default; "
        "gmsh -2 model.geo -format msh41)");
  expect(in, "$EndMeshFormat");
}

void read_physical_names(Lexer& in, File& f) {
  const long n = integer<long>(in, "the number of physical names");
  for (long k = 0; k < n; ++k) {
    const int dim = integer<int>(in, "a physical group's dimension");
    const int tag = integer<int>(in, "a physical group's tag");
    f.physical_names[{dim, tag}] = in.quoted("a physical group's name");
  }
  expect(in, "$EndPhysicalNames");
}

void read_entities(Lexer& in, File& f) {
  long counts[4];
  for (long& c : counts) c = integer<long>(in, "the number of entities");
  for (int dim = 0; dim < 4; ++dim)
    for (long k = 0; k < counts[dim]; ++k) {
      const int tag = integer<int>(in, "an entity tag");
      for (int c = 0; c < (dim == 0 ? 3 : 6); ++c) real(in, "an entity's coordinate");
      const long n_physical = integer<long>(in, "the number of physical tags");
      std::vector<int>& groups = f.entity_groups[{dim, tag}];
      for (long p = 0; p < n_physical; ++p) groups.push_back(integer<int>(in, "a physical tag"));
      if (dim > 0) {
        const long n_bounding = integer<long>(in, "the number of bounding entities");
        for (long b = 0; b < n_bounding; ++b) integer<int>(in, "a bounding entity's tag");
      }
    }
  expect(in, "$EndEntities");
}

// A node's coordinate, at most `max_magnitude` in magnitude.
double coordinate(Lexer& in, const File::Node& node, const char* axis, double max_magnitude) {
  const double value = real(in, (std::string("a node's ") + axis).c_str());
  if (std::abs(value) > max_magnitude) {
    std::ostringstream os;
    os << "node " << node.tag << ": " << axis << " = " << value << " is too large in magnitude (at most "
       << max_magnitude << ")";
    in.fail(os.str());
  }
  return value;
}

void read_nodes(Lexer& in, File& f, std::size_t max_nodes, double max_magnitude) {
  const long blocks = integer<long>(in, "the number of node blocks");
  const auto total = integer<std::size_t>(in, "the number of nodes");
  integer<std::size_t>(in, "the smallest node tag");
  integer<std::size_t>(in, "the largest node tag");
  if (total > max_nodes)
    in.fail("the file has " + std::to_string(total) + " nodes, more than the " + std::to_string(max_nodes) +
            " that the limit on degrees of freedom allows");
  for (long b = 0; b < blocks; ++b) {
    const int dim = integer<int>(in, "a node block's entity dimension");
    integer<int>(in, "a node block's entity tag");
    const int parametric = integer<int>(in, "a node block's parametric flag");
    const auto n = integer<std::size_t>(in, "a node block's size");
    if (f.nodes.size() + n > total) in.fail("the node blocks hold more nodes than the section's header says");
    const size_t first = f.nodes.size();
    for (size_t k = 0; k < n; ++k) {
      File::Node node;
      node.tag = integer<std::size_t>(in, "a node tag");
      if (!f.node_index.emplace(node.tag, f.nodes.size()).second)
        in.fail("node tag " + std::to_string(node.tag) + " appears twice");
      f.nodes.push_back(node);
    }
    const int extra = parametric ? dim : 0;  // u, (v, (w)) after x y z
    for (size_t k = 0; k < n; ++k) {
      File::Node& node = f.nodes[first + k];
      node.xy.x() = coordinate(in, node, "x", max_magnitude);
      node.xy.y() = coordinate(in, node, "y", max_magnitude);
      node.z = coordinate(in, node, "z", max_magnitude);
      for (int e = 0; e < extra; ++e) real(in, "a node's parametric coordinate");
    }
  }
  expect(in, "$EndNodes");
}

// The number of nodes of the element types a 2-D mesh may hold (0 for types not listed: not checked).
std::size_t nodes_per_element(int type) {
  switch (type) {
    case 1:
      return 2;
    case 2:
      return 3;
    case 3:
      return 4;
    case 4:
      return 4;
    case 5:
      return 8;
    case 6:
      return 6;
    case 7:
      return 5;
    case 8:
      return 3;
    case 9:
      return 6;
    case 10:
      return 9;
    case 11:
      return 10;
    case 15:
      return 1;
    case 16:
      return 8;
    case 20:
      return 9;
    case 21:
      return 10;
    default:
      return 0;
  }
}

void read_elements(Lexer& in, File& f, std::size_t max_nodes) {
  const long blocks = integer<long>(in, "the number of element blocks");
  const auto total = integer<std::size_t>(in, "the number of elements");
  integer<std::size_t>(in, "the smallest element tag");
  integer<std::size_t>(in, "the largest element tag");
  // A plane mesh of n nodes has fewer than 2n triangles, and fewer than n boundary lines and points: 4n bounds
  // what a usable file holds, and so the memory the elements take.
  const std::size_t max_elements = 4 * max_nodes + 16;
  if (total > max_elements)
    in.fail("the file has " + std::to_string(total) + " elements, more than the " + std::to_string(max_elements) +
            " that a plane mesh within the limit on degrees of freedom has");
  std::size_t read = 0;
  for (long b = 0; b < blocks; ++b) {
    File::ElementBlock block;
    block.dim = integer<int>(in, "an element block's entity dimension");
    block.entity = integer<int>(in, "an element block's entity tag");
    block.type = integer<int>(in, "an element block's element type");
    const auto n = integer<std::size_t>(in, "an element block's size");
    if (read + n > total) in.fail("the element blocks hold more elements than the section's header says");
    read += n;
    const std::size_t expected = nodes_per_element(block.type);
    for (size_t k = 0; k < n; ++k) {
      // One element per line: its tag, then its nodes (as many as its type has).
      const auto tokens = in.next_line("an element");
      block.tags.push_back(integer<std::size_t>(in, tokens[0], "an element tag"));
      if (tokens.size() < 2) in.fail("element " + std::to_string(block.tags.back()) + " has no nodes");
      if (expected != 0 && tokens.size() - 1 != expected)
        in.fail("element " + std::to_string(block.tags.back()) + " has " + std::to_string(tokens.size() - 1) +
                " nodes, but its block's type is the " + element_type_name(block.type) + " (" +
                std::to_string(expected) + " nodes)");
      std::vector<std::size_t> nodes;
      for (size_t t = 1; t < tokens.size(); ++t) {
        const auto tag = integer<std::size_t>(in, tokens[t], "a node tag");
        if (!f.node_index.count(tag))
          in.fail("element " + std::to_string(block.tags.back()) + " refers to node " + std::to_string(tag) +
                  ", which the $Nodes section does not define");
        nodes.push_back(tag);
      }
      block.nodes.push_back(std::move(nodes));
    }
    f.blocks.push_back(std::move(block));
  }
  expect(in, "$EndElements");
}

}  // namespace

std::string element_type_name(int type) {
  switch (type) {
    case 1:
      return "2-node line";
    case 2:
      return "3-node triangle";
    case 3:
      return "4-node quadrangle";
    case 4:
      return "4-node tetrahedron";
    case 5:
      return "8-node hexahedron";
    case 6:
      return "6-node prism";
    case 7:
      return "5-node pyramid";
    case 8:
      return "3-node second-order line";
    case 9:
      return "6-node second-order triangle";
    case 10:
      return "9-node second-order quadrangle";
    case 11:
      return "10-node second-order tetrahedron";
    case 15:
      return "1-node point";
    case 16:
      return "8-node second-order quadrangle";
    case 20:
      return "9-node third-order triangle";
    case 21:
      return "10-node third-order triangle";
    default:
      return "Gmsh element type " + std::to_string(type);
  }
}

File parse(const std::string& text, std::size_t max_nodes, double max_magnitude) {
  Lexer in(text);
  File f;
  if (in.at_end()) throw ParseError("the file is empty");
  if (in.token("$MeshFormat") != "$MeshFormat")
    in.fail(
        "not a Gmsh MSH file: it does not start with $MeshFormat (a .geo file must first be meshed: "
        "gmsh -2 model.geo -format msh41 -o model.msh)");
  read_format(in);
  bool nodes = false, elements = false;
  while (!in.at_end()) {
    const std::string section(in.token("a section"));
    if (section == "$PhysicalNames") {
      read_physical_names(in, f);
    } else if (section == "$Entities") {
      read_entities(in, f);
    } else if (section == "$PartitionedEntities") {
      in.fail("partitioned meshes are not supported: save the mesh without partitions");
    } else if (section == "$Nodes") {
      if (nodes) in.fail("a second $Nodes section");
      read_nodes(in, f, max_nodes, max_magnitude);
      nodes = true;
    } else if (section == "$Elements") {
      if (!nodes) in.fail("$Elements before $Nodes");
      if (elements) in.fail("a second $Elements section");
      read_elements(in, f, max_nodes);
      elements = true;
    } else if (section.size() > 1 && section[0] == '$') {
      in.skip_section("$End" + section.substr(1));
    } else {
      in.fail("expected a section such as $Nodes, got '" + section.substr(0, 40) + "'");
    }
  }
  if (!nodes || !elements)
    throw ParseError(std::string("the file has no ") + (nodes ? "$Elements" : "$Nodes") + " section");
  return f;
}

}  // namespace contact::mesh::gmsh
