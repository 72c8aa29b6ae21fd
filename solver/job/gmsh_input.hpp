// A body's Gmsh mesh in a job: {"gmsh": {"file": "model.msh" | "data": "<the file's text>" | "mesh": "name",
// "surface": "name"}}, where "mesh" names an entry of the job's table {"meshes": {"name": {"file": ...} |
// {"data": ...}}} (each file's text given once however many bodies it has). Private to the job module
// (read_meshes.cpp calls it; the rest of the body is read by read_bodies.cpp).
#pragma once

#include "../mesh/gmsh.hpp"
#include "contact/job.hpp"
#include "read.hpp"

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace contact::job {

struct GmshBody {
  mesh::Mesh mesh;
  std::vector<std::string> edges;             // physical curves on the surface's boundary (the body's edge names)
  std::vector<std::string> elsewhere;         // the file's other physical curves (for "not on this surface" messages)
  std::vector<std::string> vertices;          // physical points on the surface (the body's vertex names)
  std::vector<std::string> points_elsewhere;  // the file's other physical points
  std::string surface;
};

// The files and data strings of one job's Gmsh meshes, each read and parsed once however many bodies use it.
class GmshMeshes {
 public:
  // Refers to `limits` and, for "data" meshes, to the strings of the job being read: both must outlive it (it
  // lives while one job is parsed).
  explicit GmshMeshes(const Limits& limits) : limits_(limits) {}

  // Reads the "gmsh" object at `pointer` (a body's /mesh/gmsh) and builds the surface's mesh; nullptr after
  // reporting every problem at its pointer: the fields, a file that cannot be read or is not allowed (no
  // Limits::mesh_directory: the server), the MSH text (with its line), the surface and its curves.
  // `out` is the object's normalized copy: a "data" text is left out of it (it is in the submitted job), its size
  // given as "data_bytes". A surface is built once however many bodies name it (the bodies share it until their
  // meshes are built, after the job's size is checked against its limit: 8,192 bodies of one table entry cost one
  // surface, not 8,192, before a too large job is refused).
  std::shared_ptr<const GmshBody> read(const nlohmann::json& value, const std::string& pointer, read::Errors& errors,
                                       nlohmann::json& out);

  // Reads the job's "meshes" table at `pointer` (before the bodies): each entry's name and its one field, file
  // or data; the text is parsed when a body first uses the entry. `out` is the table's normalized copy.
  void read_table(const nlohmann::json& value, const std::string& pointer, read::Errors& errors, nlohmann::json& out);
  // After the bodies: an entry that no body used is an error at its pointer.
  void check_table_used(read::Errors& errors) const;

 private:
  struct Parsed {
    std::string error;        // empty if parsed
    bool unreadable = false;  // the error is the file's (cannot be opened, too large), not its text's
    bool reported = false;    // the error was reported, at the first body that gave this file or text
    mesh::gmsh::File file;
    const std::string* data = nullptr;  // the job's data string it was parsed from, in the job (none for a file)
  };
  Parsed& parse_file(const std::string& path);
  Parsed& parse_data(const std::string& text);  // text: a string of the job, kept by reference
  // Reports a parse's error at `pointer` the first time only (one error for one cause, however many bodies give
  // the same file or text); false if it has one.
  static bool usable(Parsed& parsed, const std::string& pointer, const std::string& message, read::Errors& errors);
  std::unique_ptr<Parsed> parse(const std::string& text) const;

  // The MSH text a body's mesh comes from, parsed; nullptr after reporting why not (at `pointer`, the file or
  // data field). `label` names the mesh in later messages.
  struct Source {
    bool file = false;
    const std::string* text = nullptr;  // the path or the data, a string of the job
  };
  const Parsed* resolve(const Source& source, const std::string& pointer, read::Errors& errors, std::string& label);
  // The table entry `name` at `pointer` (the body's /mesh/gmsh/mesh); nullptr after reporting an unknown name, or
  // when the entry's own problem is reported at /meshes/<name>.
  const Parsed* from_table(const std::string& name, const std::string& pointer, read::Errors& errors,
                           std::string& label);

  // A surface of one parsed text, built once: its mesh, or the errors found (reported at each body that names it).
  struct BuiltSurface {
    std::shared_ptr<const GmshBody> body;
    std::vector<std::string> errors;
    bool found = false;  // the surface exists (its errors are the mesh's, not the name's)
  };
  const BuiltSurface& surface_of(const Parsed& parsed, const std::string& surface);

  struct TableEntry {
    std::string pointer;           // /meshes/<name>
    std::optional<Source> source;  // unset when the entry's fields are bad (reported at its pointer)
    bool used = false;
    bool resolved = false;
    const Parsed* parsed = nullptr;  // once resolved: nullptr if its problem was reported
    std::string label;
  };

  const Limits& limits_;
  std::map<std::string, std::unique_ptr<Parsed>> files_;                    // by resolved path
  std::multimap<std::size_t, std::unique_ptr<Parsed>> data_;                // by the hash of the text
  std::map<std::string, TableEntry> table_;                                 // the job's "meshes", by name
  std::map<std::pair<const Parsed*, std::string>, BuiltSurface> surfaces_;  // by text and surface name
  bool table_given_ = false;                                                // the job has "meshes" (maybe malformed)
  bool table_incomplete_ = false;  // "meshes" not an object, or an entry refused for its name: reported there
};

}  // namespace contact::job
