// The reader of the job format v1 (docs/job-format.md, api/job.schema.json): JSON -> Problem. Private to the job
// module. job.cpp holds the entry points of job.hpp and the reader's frame (run, the header, the model, the limits
// on work); read_options.cpp, read_bodies.cpp, read_meshes.cpp and read_contacts.cpp read the parts of a job.
//
// Validation runs in phases so that every problem is reported at once and nothing expensive happens for a job
// that is already known to be bad:
//   1. read every field (types, ranges, unknown fields) without generating any mesh (a Gmsh mesh is read here,
//      its size bounded by the limit on degrees of freedom, since its edge names come from the file);
//   2. count the degrees of freedom from the mesh sizes alone and refuse the job if over the limit;
//   3. generate the meshes and check their cells;
//   4. check that each body is restrained against rigid motion (needs the mesh; only for bodies with no
//      other error, since a broken body would give a misleading answer);
//   5. resolve the contact pairs' references to bodies and edges.
// Problem::normalized is the submitted document with every default written in.
#pragma once

#include <array>
#include <cstddef>
#include <chrono>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "gmsh_input.hpp"
#include "contact/job.hpp"
#include "read.hpp"

namespace contact::job::detail {

using nlohmann::json;
using read::bounded_int;
using read::child;
using read::choice;
using read::Errors;
using read::Fields;
using read::format_number;
using read::identifier;
using read::join_names;
using read::name_problem;
using read::positive;
using Point = mesh::Point;

// Writes a default into the normalized copy; a no-op where the copy is not an object (the job is bad then and
// the copy is never used).
void set_default(json& object, const std::string& key, json value);

// ---------------------------------------------------------------------------------------------------------
// Phase 1 records: what was read of a body before any mesh exists.

struct MeshInput {
  enum class Kind { unknown, block, arrays, gmsh };
  Kind kind = Kind::unknown;
  bool valid = false;        // every field read without error: the mesh can be built
  double dofs = -1.0;        // 2 * nodes, known from the sizes alone; < 0 if unknown
  bool edges_known = false;  // the edge names are known (even if other fields are bad)
  std::vector<std::string> edge_names;
  std::vector<std::string> vertex_names;  // named vertices (a block's corners, an explicit mesh's "vertices")
  // block
  mesh::BlockSpec block;
  std::map<std::string, std::string> curve_pointers;  // edge name -> pointer of its curve object
  // explicit arrays
  std::vector<Point> nodes;
  std::vector<mesh::Cell> quads;
  std::vector<std::pair<std::string, std::vector<std::array<int, 2>>>> edge_pairs;
  std::map<std::string, int> vertices;             // named vertices of an explicit mesh: name -> node
  std::map<std::string, mesh::Curve> edge_curves;  // "curves" given as an arc or a parabola, by edge
  std::set<std::string> chord_edges;               // "curves" given as "chords"
  // gmsh: the surface's mesh, built while reading (gmsh_input.hpp), shared by the bodies that name it until
  // build_mesh copies it
  std::shared_ptr<const GmshBody> gmsh;
};

// The first condition given at an edge or vertex of a body, and whether every condition there so far is a load
// alone (several loads on one place add; a displacement or "free" stands alone).
struct PlaceUse {
  std::string pointer;
  bool loads_only = false;
};

struct BodyInput {
  std::string pointer;
  bool has_name = false;
  Body body;
  MeshInput mesh;
  std::vector<std::string> free_motions;  // rigid motions its displacement conditions leave free (a floating body)
  std::vector<std::string> condition_pointers;  // per entry of body.boundary: its pointer (/bodies/i/boundary/j)
  std::string body_force_pointer;               // /bodies/i/body_force when it has a history, else ""
  std::vector<std::string> live_pointers;       // the "live" flags that are true (a collapse analysis's loads)
};

// Questions on what was read of a mesh (read_meshes.cpp).
bool has_edge(const MeshInput& m, const std::string& name);
// For a Gmsh body: why `name`, a physical curve (or, for a vertex, a physical point) of the file, is not one of
// its edges (vertices); nullopt otherwise.
std::optional<std::string> gmsh_elsewhere(const MeshInput& m, const std::string& name, bool vertex = false);

// Reads a node index of an explicit mesh, checked against its node count (out of range: an error, nullopt).
struct NodeIndex {
  size_t node_count;
  Errors& errors;
  std::optional<int> operator()(const json& v, const std::string& ptr, const std::string& what) const;
};

class JobReader {
 public:
  JobReader(const json& job, const Limits& limits)
      : job_(job), limits_(limits), normalized_(job), started_(std::chrono::steady_clock::now()), gmsh_(limits) {}
  ParseResult run();
  // Validation ran past Limits::max_validation_seconds: the job is refused (once, naming `during`), and true
  // from then on, so that each phase (and the loops over bodies and pairs) stops.
  bool out_of_time(const char* during);

 private:
  // job.cpp: the frame, the header and the model, the normalized copy's parts
  void check_work_limits();
  ParseResult finish();
  void read_header(const Fields& top);
  void read_strict(const Fields& top);
  void check_initial_gaps();
  void read_model(const Fields& top);
  json& sub_object(json& parent, const std::string& key);
  json& element(json& array, size_t index);
  json& discard();

  // read_options.cpp: solver, adaptivity, loading, parallel, output
  void read_solver(const Fields& top);
  void read_solver_fields(const json& value, const std::string& pointer, json& out);
  void read_method(const json& value, const std::string& pointer);
  void read_gamma(const json& value, const std::string& pointer);
  void read_enforcement(const json& value, const std::string& pointer);
  void write_solver_defaults(json& out);
  void resolve_method_defaults();
  void read_adaptivity(const json& value, const std::string& pointer);
  void read_adaptive_bodies(const json& value, const std::string& pointer);
  void read_target_error(const json& value, const std::string& pointer, const json* stop_tolerance, json& out);
  void resolve_marking(const std::string& given, bool delta, bool max_level, bool max_steps, json& out);
  void write_adaptivity_defaults(json& out);
  void read_robin(const json& value, const std::string& pointer);
  void read_augmented_lagrangian(const json& value, const std::string& pointer);
  void read_interface_solver(const json& value, const std::string& pointer);
  void read_penalty(const json& value, const std::string& pointer, json& out);
  void read_parallel(const Fields& top);
  void read_loading(const Fields& top);
  void read_loading_steps(const json& value, const std::string& pointer);
  void read_output(const Fields& top);
  void check_result_size();
  void check_interface_memory();
  void read_progress_pairs(const json& value, const std::string& pointer);

  // read_bodies.cpp: bodies, materials, boundary conditions; the checks on the built bodies
  void read_bodies(const Fields& top);
  void read_body(const json& value, BodyInput& in, json& out);
  void read_material(const json& value, const std::string& pointer, Material& material);
  void read_boundary(const json& value, const std::string& pointer, BodyInput& in);
  void read_condition(const json& value, const std::string& pointer, BodyInput& in,
                      std::map<std::string, PlaceUse>& first_pointer_of_place);
  void read_condition_place(const Fields& f, bool at_vertex, const MeshInput& mesh, BoundaryCondition& bc,
                            std::map<std::string, PlaceUse>& first_pointer_of_place);
  bool condition_kinds_allowed(const Fields& f, const std::string& pointer, bool at_vertex);
  void read_condition_values(const Fields& f, const std::string& pointer, BoundaryCondition& bc);
  void check_loads_off_supports(const Fields& f, const std::string& pointer, const BoundaryCondition& bc);
  void check_restrained(BodyInput& in);
  void check_loads_reach_the_body(const BodyInput& in);
  void check_floating_bodies();

  // read_meshes.cpp: blocks and their curves, explicit arrays, Gmsh surfaces; building and checking the meshes
  void read_mesh(const json& value, const std::string& pointer, MeshInput& m, json& out);
  void read_block(const json& value, const std::string& pointer, MeshInput& m);
  bool read_block_corners(const Fields& f, mesh::BlockSpec& spec);
  void read_block_size(const Fields& f, MeshInput& m);
  void read_block_grading(const json& value, const std::string& pointer, mesh::BlockSpec& spec);
  void fit_block_curves(MeshInput& m);
  void read_gmsh(const json& value, const std::string& pointer, MeshInput& m, json& out);
  std::optional<long long> read_count(const json& value, const std::string& pointer, const std::string& what);
  std::optional<mesh::Curve> read_curve(const json& value, const std::string& pointer, const std::string& edge,
                                        MeshInput& m);
  void read_edge_curves(const Fields& f, MeshInput& m, json& out);
  void fit_explicit_curves(const MeshInput& m, const std::string& pointer, mesh::Mesh& mesh);
  void read_arrays(const json& value, const std::string& pointer, MeshInput& m, json& out);
  size_t read_nodes(const json& nodes, const std::string& pointer, MeshInput& m);
  void read_quads(const json& quads, const std::string& pointer, const NodeIndex& index, MeshInput& m);
  void read_named_edges(const Fields& f, bool nodes_ok, const NodeIndex& index, MeshInput& m, json& out);
  void read_named_vertices(const Fields& f, bool nodes_ok, const NodeIndex& index, MeshInput& m, json& out);
  bool no_side_twice(const std::string& name, const std::vector<std::array<int, 2>>& pairs, const std::string& pointer);
  template <typename Index>
  void read_edge_set(const std::string& name, const json& value, const std::string& pointer, bool nodes_ok,
                     const Index& index, MeshInput& m);
  void build_mesh(BodyInput& in);
  void check_arrays(const mesh::Mesh& mesh, const std::string& pointer);

  // read_contacts.cpp: contact pairs and their gaps
  struct EdgeRef {
    int body = -1;
    std::string edge;
  };
  std::optional<EdgeRef> resolve(const json& value, const std::string& pointer, const std::string& what);
  bool bodies_all_named() const;
  void read_contacts(const Fields& top);
  void read_gap(const Fields& contact, GapSpec& gap, json& out);
  void check_pairs_face();

  // read_friction.cpp: a pair's friction, a condition's load history, and what they require of the rest
  void read_friction(const Fields& contact, FrictionSpec& friction);
  void read_history(const Fields& condition, std::vector<double>& history);
  // A load's "live" flag (read_collapse.cpp): true marks a live load of the collapse analysis; a load only (not a
  // displacement, not "free"), without a history of its own.
  bool read_live(const Fields& condition);
  void read_collapse(const Fields& top);  // "collapse"
  void check_collapse();                  // after everything: live loads and the collapse section agree
  void read_body_force(const json& value, const std::string& pointer, BodyInput& in);
  void check_friction_and_histories();

  const json& job_;
  const Limits& limits_;
  json normalized_;
  std::string collapse_pointer_;  // "/collapse" when the job has one
  json discarded_;
  Errors errors_;
  Problem problem_;
  // The job's "method" and "enforcement": their defaults depend on the rest of the job (resolve_method_defaults),
  // and the checks that involve them point at them. `pointer` is set once the field is present (the enforcement's
  // stands at "/solver" until then), `valid` once its name was read without error.
  struct GivenSetting {
    std::string pointer;
    bool valid = false;
  };
  GivenSetting method_, enforcement_{"/solver"};
  std::vector<std::string> friction_pointers_;  // per contact pair of problem_.contacts (empty: frictionless)
  std::vector<std::string> contact_pointers_;   // per contact pair of problem_.contacts: /contacts/k
  // One error for one cause: what a part refused whole (over a limit, of the wrong type) or read only in part
  // leaves unknown, so the checks that depend on it are not run (docs/job-format.md, "Validation and errors").
  const std::chrono::steady_clock::time_point started_;
  bool timed_out_ = false;
  bool bodies_listed_ = false;     // the bodies' list was read (not refused whole); names may still be missing
  bool contacts_complete_ = true;  // every contact pair was read and resolved: the bodies' contacts are known
  bool loading_read_ = true;       // the load steps were read without error: their number is known
  std::vector<BodyInput> inputs_;
  // The named bodies' indices in inputs_ (the first of a name), made by resolve() once the bodies are read: a wall
  // of 4,129 bricks has 24,384 contact ends to resolve.
  std::map<std::string, size_t> body_index_;
  bool body_index_made_ = false;
  GmshMeshes gmsh_;
};

}  // namespace contact::job::detail
