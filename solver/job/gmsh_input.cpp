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

// The normalized copy of an object holding a mesh text as "data": the text is in the submitted job already, so
// the copy (stored with it in the result file, answered by validation) gives only its size.
void leave_out_data(json& out, const std::string& text) {
  if (!out.is_object() || !out.contains("data")) return;
  out.erase("data");
  out["data_bytes"] = text.size();
}

}  // namespace

std::unique_ptr<GmshMeshes::Parsed> GmshMeshes::parse(const std::string& text) const {
  auto p = std::make_unique<Parsed>();
  try {
    // Node coordinates are bounded like every number of the job.
    p->file =
        mesh::gmsh::parse(text, static_cast<std::size_t>(std::max(0L, limits_.max_dofs / 2)), read::kMaxMagnitude);
  } catch (const mesh::gmsh::ParseError& e) {
    p->error = e.what();
  }
  return p;
}

GmshMeshes::Parsed& GmshMeshes::parse_file(const std::string& path) {
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

GmshMeshes::Parsed& GmshMeshes::parse_data(const std::string& text) {
  const std::size_t hash = std::hash<std::string>{}(text);
  const auto [first, last] = data_.equal_range(hash);
  for (auto it = first; it != last; ++it)
    if (*it->second->data == text) return *it->second;
  auto parsed = parse(text);
  parsed->data = &text;
  return *data_.emplace(hash, std::move(parsed))->second;
}

void GmshMeshes::read_table(const json& value, const std::string& pointer, read::Errors& errors, json& out) {
  table_given_ = true;
  if (!value.is_object()) {
    errors.add(pointer, "meshes must be an object {\"name\": {\"file\": ...} or {\"data\": ...}, ...}, got " +
                            read::type_name(value));
    table_incomplete_ = true;
    return;
  }
  for (const auto& item : value.items()) {
    const std::string p = read::child(pointer, item.key());
    if (auto problem = read::name_problem(item.key(), "mesh name", limits_.max_name_length, false)) {
      errors.add(p, *problem);  // not an entry: a body that names no entry is the same cause
      table_incomplete_ = true;
      continue;
    }
    TableEntry& entry = table_[item.key()];
    entry.pointer = p;
    const size_t before = errors.size();
    read::Fields f(item.value(), p, "a mesh", {"file", "data"}, errors);
    if (!f.ok() || errors.size() != before) continue;
    if (f.has("file") == f.has("data")) {
      errors.add(p,
                 "give exactly one of file (the .msh file's path, relative to the job file) or data (the .msh "
                 "file's text)");
      continue;
    }
    const std::string key = f.has("file") ? "file" : "data";
    if (!read::string(*f.find(key), f.at(key), key, errors)) continue;
    entry.source = Source{key == "file", &f.find(key)->get_ref<const std::string&>()};
    if (out.is_object() && out.contains(item.key())) leave_out_data(out[item.key()], *entry.source->text);
  }
}

void GmshMeshes::check_table_used(read::Errors& errors) const {
  for (const auto& [name, entry] : table_)
    if (!entry.used)
      errors.add(entry.pointer, "mesh '" + read::shown(name) +
                                    "' is used by no body (a body uses it as {\"gmsh\": "
                                    "{\"mesh\": \"" +
                                    read::shown(name) + "\", \"surface\": ...}}); remove it or use it");
}

bool GmshMeshes::usable(Parsed& parsed, const std::string& pointer, const std::string& message, read::Errors& errors) {
  if (parsed.error.empty()) return true;
  if (!parsed.reported) errors.add(pointer, message);
  parsed.reported = true;
  return false;
}

const GmshMeshes::Parsed* GmshMeshes::resolve(const Source& source, const std::string& pointer, read::Errors& errors,
                                              std::string& label) {
  const std::string& text = *source.text;
  if (!source.file) {
    Parsed& parsed = parse_data(text);
    if (!usable(parsed, pointer, "the mesh data (MSH text): " + parsed.error, errors)) return nullptr;
    label = "data";
    return &parsed;
  }
  if (!limits_.mesh_directory) {
    errors.add(pointer,
               "a gmsh mesh cannot be read from a file here: the server reads no files for a job; send the "
               ".msh file's text as \"data\" instead of \"file\"");
    return nullptr;
  }
  if (text.empty()) {
    errors.add(pointer, "file must name a .msh file, got an empty string");
    return nullptr;
  }
  const fs::path given(text);
  const fs::path path = (given.is_absolute() ? given : fs::path(*limits_.mesh_directory) / given).lexically_normal();
  Parsed& parsed = parse_file(path.string());
  label = "'" + read::shown(text) + "'";
  const std::string resolved = path.string() != text ? " (" + read::shown(path.string()) + ")" : "";
  if (!usable(parsed, pointer, "the mesh file " + label + resolved + (parsed.unreadable ? " " : ": ") + parsed.error,
              errors))
    return nullptr;
  return &parsed;
}

const GmshMeshes::Parsed* GmshMeshes::from_table(const std::string& name, const std::string& pointer,
                                                 read::Errors& errors, std::string& label) {
  auto it = table_.find(name);
  if (it == table_.end()) {
    // A table refused whole, or an entry refused for its name, may be the mesh this body names: reported there.
    if (table_incomplete_) return nullptr;
    std::vector<std::string> names;
    for (const auto& [known, entry] : table_) names.push_back("'" + read::shown(known) + "'");
    std::string known = "its meshes are " + read::join_names(names);
    if (names.empty())
      known = table_given_ ? "the table is empty"
                           : "it has no \"meshes\" table (give {\"meshes\": {\"" + read::shown(name) +
                                 "\": {\"data\": ...}}} at the top level)";
    errors.add(pointer, "the job has no mesh '" + read::shown(name) + "' in its \"meshes\" table; " + known);
    return nullptr;
  }
  TableEntry& entry = it->second;
  entry.used = true;
  if (!entry.source) return nullptr;  // its fields are bad: reported at /meshes/<name>
  if (!entry.resolved) {
    // Its problems are the entry's: reported once, at its field, however many bodies use it.
    entry.parsed =
        resolve(*entry.source, read::child(entry.pointer, entry.source->file ? "file" : "data"), errors, entry.label);
    entry.resolved = true;
    if (!entry.source->file) entry.label = "'" + read::shown(name) + "'";
  }
  label = entry.label;
  return entry.parsed;
}

const GmshMeshes::BuiltSurface& GmshMeshes::surface_of(const Parsed& parsed, const std::string& surface) {
  const auto key = std::make_pair(&parsed, surface);
  auto it = surfaces_.find(key);
  if (it != surfaces_.end()) return it->second;
  BuiltSurface built;
  mesh::gmsh::Surface s = mesh::gmsh::surface(parsed.file, surface);
  built.found = s.found;
  built.errors = std::move(s.errors);
  if (built.errors.empty()) {
    auto body = std::make_shared<GmshBody>();
    body->mesh = std::move(s.mesh);
    body->edges = std::move(s.edges);
    body->elsewhere = std::move(s.elsewhere);
    body->vertices = std::move(s.vertices);
    body->points_elsewhere = std::move(s.points_elsewhere);
    body->surface = surface;
    built.body = std::move(body);
  }
  return surfaces_.emplace(key, std::move(built)).first->second;
}

std::shared_ptr<const GmshBody> GmshMeshes::read(const json& value, const std::string& pointer, read::Errors& errors,
                                                 json& out) {
  const size_t before = errors.size();
  read::Fields f(value, pointer, "gmsh", {"file", "data", "mesh", "surface"}, errors);
  if (!f.ok()) return nullptr;
  std::optional<std::string> surface;
  if (const json* s = f.require("surface", "the name of the physical surface that is this body"))
    surface = read::string(*s, f.at("surface"), "surface", errors);
  if (surface)
    if (auto problem = read::control_character_problem(*surface, "surface")) errors.add(f.at("surface"), *problem);
  if (f.has("file") + f.has("data") + f.has("mesh") != 1) {
    errors.add(pointer,
               "give exactly one of mesh (the name of an entry of the job's \"meshes\" table), file (the "
               ".msh file's path, relative to the job file) or data (the .msh file's text)");
    return nullptr;
  }
  const std::string key = f.has("mesh") ? "mesh" : f.has("file") ? "file" : "data";
  const auto text = read::string(*f.find(key), f.at(key), key, errors);
  if (!text || !surface || errors.size() != before) return nullptr;

  // The job's own string (text is a copy): the cache refers to it, and the job outlives the parse.
  const std::string& given = f.find(key)->get_ref<const std::string&>();
  std::string label;  // names the mesh in messages
  const Parsed* parsed = key == "mesh" ? from_table(given, f.at(key), errors, label)
                                       : resolve(Source{key == "file", &given}, f.at(key), errors, label);
  if (key == "data") leave_out_data(out, given);
  if (!parsed) return nullptr;
  const BuiltSurface& built = surface_of(*parsed, *surface);
  for (const auto& e : built.errors)
    errors.add(built.found ? pointer : f.at("surface"), "the mesh " + label + ": " + e);
  return built.body;
}

}  // namespace contact::job
