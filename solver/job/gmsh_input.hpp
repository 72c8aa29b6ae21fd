// A body's Gmsh mesh in a job: {"gmsh": {"file": "model.msh" | "data": "<the file's text>", "surface": "name"}}.
// Private to the job module (read_meshes.cpp calls it; the rest of the body is read by read_bodies.cpp).
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
  std::vector<std::string> edges;      // physical curves on the surface's boundary (the body's edge names)
  std::vector<std::string> elsewhere;  // the file's other physical curves (for "not on this surface" messages)
  std::vector<std::string> vertices;   // physical points on the surface (the body's vertex names)
  std::vector<std::string> points_elsewhere;  // the file's other physical points
  std::string surface;
};

// The files and data strings of one job's Gmsh meshes, each read and parsed once however many bodies use it.
class GmshMeshes {
 public:
  // Refers to `limits` and, for "data" meshes, to the strings of the job being read: both must outlive it (it
  // lives while one job is parsed).
  explicit GmshMeshes(const Limits& limits) : limits_(limits) {}

  // Reads the "gmsh" object at `pointer` (a body's /mesh/gmsh) and builds the surface's mesh; nullopt after
  // reporting every problem at its pointer: the fields, a file that cannot be read or is not allowed (no
  // Limits::mesh_directory: the server), the MSH text (with its line), the surface and its curves.
  std::optional<GmshBody> read(const nlohmann::json& value, const std::string& pointer, read::Errors& errors);

 private:
  struct Parsed {
    std::string error;  // empty if parsed
    bool unreadable = false;  // the error is the file's (cannot be opened, too large), not its text's
    mesh::gmsh::File file;
    const std::string* data = nullptr;  // the job's data string it was parsed from, in the job (none for a file)
  };
  const Parsed& parse_file(const std::string& path);
  const Parsed& parse_data(const std::string& text);  // text: a string of the job, kept by reference
  std::unique_ptr<Parsed> parse(const std::string& text) const;

  const Limits& limits_;
  std::map<std::string, std::unique_ptr<Parsed>> files_;             // by resolved path
  std::multimap<std::size_t, std::unique_ptr<Parsed>> data_;         // by the hash of the text
};

}  // namespace contact::job
