#include "gmsh_input.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

namespace contact::job {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The bytes of a file, or an error message.
std::string read_bytes(const fs::path& path, std::size_t max_bytes, std::string& error) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    error = "is a directory, not a .msh file";
    return {};
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = std::string("cannot be opened: ") + std::strerror(errno);
    return {};
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) {
    error = "cannot be read";
    return {};
  }
  if (static_cast<std::size_t>(size) > max_bytes) {
    error = "is " + std::to_string(size) + " bytes, more than the limit of " + std::to_string(max_bytes) + " bytes";
    return {};
  }
  in.seekg(0);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), size)) error = std::string("cannot be read: ") + std::strerror(errno);
  return text;
}

}  // namespace

std::unique_ptr<GmshMeshes::Parsed> GmshMeshes::parse(const std::string& text) const {
  auto p = std::make_unique<Parsed>();
  try {
    // Node coordinates are bounded like every number of the job.
    p->file = mesh::gmsh::parse(text, static_cast<std::size_t>(std::max(0L, limits_.max_dofs / 2)),
                                read::kMaxMagnitude);
  } catch (const mesh::gmsh::ParseError& e) {
    p->error = e.what();
  }
  return p;
}

const GmshMeshes::Parsed& GmshMeshes::parse_file(const std::string& path) {
  auto it = files_.find(path);
  if (it == files_.end()) {
    std::string read_error;
    const std::string text = read_bytes(path, limits_.max_mesh_file_bytes, read_error);
    std::unique_ptr<Parsed> parsed;
    if (read_error.empty()) {
      parsed = parse(text);
    } else {
      parsed = std::make_unique<Parsed>();
      parsed->error = read_error;
      parsed->unreadable = true;
    }
    it = files_.emplace(path, std::move(parsed)).first;
  }
  return *it->second;
}

const GmshMeshes::Parsed& GmshMeshes::parse_data(const std::string& text) {
  const std::size_t hash = std::hash<std::string>{}(text);
  const auto [first, last] = data_.equal_range(hash);
  for (auto it = first; it != last; ++it)
    if (*it->second->data == text) return *it->second;
  auto parsed = parse(text);
  parsed->data = &text;
  return *data_.emplace(hash, std::move(parsed))->second;
}

std::optional<GmshBody> GmshMeshes::read(const json& value, const std::string& pointer, read::Errors& errors) {
  const size_t before = errors.size();
  read::Fields f(value, pointer, "gmsh", {"file", "data", "surface"}, errors);
  if (!f.ok()) return std::nullopt;
  std::optional<std::string> surface;
  if (const json* s = f.require("surface", "the name of the physical surface that is this body"))
    surface = read::string(*s, f.at("surface"), "surface", errors);
  if (surface)
    if (auto problem = read::control_character_problem(*surface, "surface")) errors.add(f.at("surface"), *problem);
  if (f.has("file") == f.has("data")) {
    errors.add(pointer, "give exactly one of file (the .msh file's path, relative to the job file) or data (the "
                        ".msh file's text)");
    return std::nullopt;
  }
  const std::string source_pointer = f.at(f.has("file") ? "file" : "data");
  const auto text = read::string(*f.find(f.has("file") ? "file" : "data"), source_pointer,
                                 f.has("file") ? "file" : "data", errors);
  if (!text || !surface || errors.size() != before) return std::nullopt;

  const Parsed* parsed = nullptr;
  std::string source;  // names the mesh in messages
  if (f.has("file")) {
    if (!limits_.mesh_directory) {
      errors.add(source_pointer,
                 "a gmsh mesh cannot be read from a file here: the server reads no files for a job; send the .msh "
                 "file's text as \"data\" instead of \"file\"");
      return std::nullopt;
    }
    if (text->empty()) {
      errors.add(source_pointer, "file must name a .msh file, got an empty string");
      return std::nullopt;
    }
    const fs::path given(*text);
    const fs::path path = (given.is_absolute() ? given : fs::path(*limits_.mesh_directory) / given).lexically_normal();
    parsed = &parse_file(path.string());
    source = "'" + read::shown(*text) + "'";
    if (!parsed->error.empty()) {
      errors.add(source_pointer, "the mesh file " + source +
                                     (path.string() != *text ? " (" + read::shown(path.string()) + ")" : "") +
                                     (parsed->unreadable ? " " : ": ") + parsed->error);
      return std::nullopt;
    }
  } else {
    // The job's own string (text is a copy): the cache refers to it, and the job outlives the parse.
    parsed = &parse_data(f.find("data")->get_ref<const std::string&>());
    source = "data";
    if (!parsed->error.empty()) {
      errors.add(source_pointer, "the mesh data (MSH text): " + parsed->error);
      return std::nullopt;
    }
  }
  mesh::gmsh::Surface s = mesh::gmsh::surface(parsed->file, *surface);
  if (!s.errors.empty()) {
    for (const auto& e : s.errors) errors.add(s.found ? pointer : f.at("surface"), "the mesh " + source + ": " + e);
    return std::nullopt;
  }
  GmshBody out;
  out.mesh = std::move(s.mesh);
  out.edges = std::move(s.edges);
  out.elsewhere = std::move(s.elsewhere);
  out.vertices = std::move(s.vertices);
  out.points_elsewhere = std::move(s.points_elsewhere);
  out.surface = *surface;
  return out;
}

}  // namespace contact::job
