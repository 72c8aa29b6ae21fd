// Gmsh meshes: the MSH 4.1 file format (ASCII) read into plain arrays, and one physical surface of such a file
// taken as a body's Mesh, with its physical curves as named edge sets.
//
// Why a reader of our own and not Gmsh's library (libgmsh, Debian's libgmsh-dev): the library keeps one
// process-wide model behind gmsh::initialize()/gmsh::open() (not usable from the server's concurrent job threads
// without a global lock), reads only files (the server takes the mesh's text inside the job), and brings about
// 100 MB of OpenCASCADE, FLTK and OpenGL libraries into the runtime image for what is five sections of a text
// format. The reader bounds its memory by the text's size and the job's degree-of-freedom limit and reports
// every problem with a line number or a Gmsh element tag. tests/unit/test_gmsh.cpp checks it against libgmsh's own
// reading of the examples where the library is installed (docs/job-format.md, "Gmsh meshes").
//
// Layering: like the rest of mesh/, nothing here knows of finite elements or of the job format.
#pragma once

#include "contact/mesh.hpp"

#include <cstddef>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace contact::mesh::gmsh {

// A malformed or unsupported file: the message says what and where ("line 12: ...").
class ParseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The contents of a MSH 4.1 file that a 2-D body needs. Tags are Gmsh's (positive, not necessarily contiguous).
struct File {
  struct Node {
    std::size_t tag = 0;
    Point xy = Point::Zero();
    double z = 0.0;
  };
  struct ElementBlock {  // the elements of one type on one geometric entity
    int dim = 0, entity = 0, type = 0;
    std::vector<std::size_t> tags;
    std::vector<std::vector<std::size_t>> nodes;  // node tags per element
  };
  std::map<std::pair<int, int>, std::string> physical_names;      // (dim, physical tag) -> name
  std::map<std::pair<int, int>, std::vector<int>> entity_groups;  // (dim, entity tag) -> its physical tags
  std::vector<Node> nodes;
  std::unordered_map<std::size_t, std::size_t> node_index;  // node tag -> index into nodes
  std::vector<ElementBlock> blocks;
};

// Reads MSH 4.1 ASCII text (what `gmsh -2 x.geo -format msh41` writes). Throws ParseError for anything else:
// another version (2.2, 4.0), a binary file, a partitioned mesh, malformed sections, an element on an unknown
// node or with the wrong number of nodes for its type, more than max_nodes nodes or 4 max_nodes + 16 elements
// (checked from the sections' headers, before they are read), a node coordinate larger than max_magnitude in
// magnitude (the job reader passes its bound on every number, read::kMaxMagnitude).
File parse(const std::string& text, std::size_t max_nodes, double max_magnitude = std::numeric_limits<double>::max());

// The name of a Gmsh element type for messages ("6-node second-order triangle").
std::string element_type_name(int type);

// One physical surface of a file as a body's mesh.
struct Surface {
  bool found = false;                         // the file has a physical surface of that name
  Mesh mesh;                                  // nodes, cells and an edge set per physical curve on its boundary
  std::vector<std::string> edges;             // the names of those edge sets, in the order of their physical tags
  std::vector<std::string> elsewhere;         // physical curves of the file that are not on this surface's boundary
  std::vector<std::string> vertices;          // physical points on this surface (mesh.vertices), by physical tag
  std::vector<std::string> points_elsewhere;  // physical points of the file that are not on this surface
  std::vector<std::string> errors;            // empty if and only if the mesh is usable
};

// Builds the mesh of the physical surface `name` (all its surface entities): its 3-node triangles and 4-node
// quadrangles, renumbered from 0 in the order of the node tags, counter-clockwise (a surface meshed with its
// normal along -z has every cell reversed; cells of both orientations are an error). Each physical curve with
// 2-node line elements on this surface's boundary becomes an edge set of that name (mesh::add_edge_set: it must
// be one open chain, or one closed loop, stored from the first node of its first line); its segments on other
// surfaces are not this body's. Each physical point whose point is a
// node of this surface becomes a named vertex (Mesh::vertices: point loads and supports). Every problem is
// reported in `errors` naming the physical group and the Gmsh element tags: an unknown name (the known ones
// listed), a 3-D or second-order element, nodes off a plane z = const, degenerate, inverted or non-convex cells,
// a side shared by more than two cells, a body in more than one piece, a curve through the surface's interior, a
// curve in several pieces, a physical point with several points on the surface.
Surface surface(const File& file, const std::string& name);

}  // namespace contact::mesh::gmsh
