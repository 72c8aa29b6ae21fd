// The web page and what it is made of: GET / (the page for a browser, the links for an API client), the page's
// files under /web/ and the example jobs under /v1/examples, all compiled into the binary (assets.hpp).
// The page is static: it talks to the API like any other client (with the bearer token the user gives it), so
// these handlers know nothing of jobs.
#include "http/routes.hpp"

#include "http/problem_document.hpp"
#include "routes/assets.hpp"

#include "contact/solve.hpp"

#include <cstdio>

namespace contactd {

namespace {

// The page loads scripts, styles and data from this server only and never runs inline code; nothing may frame it.
constexpr const char* kContentSecurityPolicy =
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; connect-src 'self'; "
    "form-action 'none'; frame-ancestors 'none'; base-uri 'none'";

// A strong validator of an embedded file's bytes (64-bit FNV-1a): they change only with the binary.
std::string etag_of(std::string_view data) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : data) h = (h ^ c) * 1099511628211ull;
  char text[24];
  std::snprintf(text, sizeof text, "\"%016llx\"", static_cast<unsigned long long>(h));
  return text;
}

const assets::File* find(const std::vector<assets::File>& files, std::string_view name) {
  for (const auto& f : files)
    if (f.name == name) return &f;
  return nullptr;
}

// An example as served: the Gmsh meshes its bodies name by "file" go into the job's "meshes" table with their
// text as "data", each file once under its name without ".msh" (a job sent to the server carries its meshes: the
// server reads no files for a job), and the bodies refer to them by that name.
std::string with_meshes(const std::string& text) {
  auto job = nlohmann::ordered_json::parse(text);  // keeps the fields in the file's order
  nlohmann::ordered_json meshes = job.value("meshes", nlohmann::ordered_json::object());
  for (auto& body : job.at("bodies")) {
    if (!body.contains("mesh") || !body["mesh"].contains("gmsh")) continue;
    auto& gmsh = body["mesh"]["gmsh"];
    if (!gmsh.is_object() || !gmsh.contains("file")) continue;
    const std::string file = gmsh["file"].get<std::string>();
    const auto* mesh = find(assets::example_meshes(), file);
    if (!mesh) continue;  // left as it is: the server's validation names the file
    const bool msh = file.size() > 4 && file.compare(file.size() - 4, 4, ".msh") == 0;
    const std::string name = msh ? file.substr(0, file.size() - 4) : file;
    meshes[name] = {{"data", std::string(mesh->data)}};
    nlohmann::ordered_json by_name;
    for (auto& [key, value] : gmsh.items()) {
      if (key == "file")
        by_name["mesh"] = name;
      else
        by_name[key] = value;
    }
    gmsh = std::move(by_name);
  }
  nlohmann::ordered_json out;  // "meshes" just before "bodies"
  for (auto& [key, value] : job.items()) {
    if (key == "meshes") continue;
    if (key == "bodies" && !meshes.empty()) out["meshes"] = meshes;
    out[key] = value;
  }
  return out.dump(2) + "\n";
}

// The examples as served (with_meshes). Built once; owns the texts.
const std::vector<assets::File>& served_examples() {
  static const std::vector<std::string> texts = [] {
    std::vector<std::string> out;
    for (const auto& e : assets::examples()) {
      std::string text(e.data);
      out.push_back(text.find("\"gmsh\"") != std::string::npos ? with_meshes(text) : std::move(text));
    }
    return out;
  }();
  static const std::vector<assets::File> files = [] {
    std::vector<assets::File> out;
    for (size_t k = 0; k < assets::examples().size(); ++k)
      out.push_back({assets::examples()[k].name, assets::examples()[k].content_type, texts[k]});
    return out;
  }();
  return files;
}

// Sends an embedded file with its validator; 304 when the client has it already.
void send_file(const httplib::Request& req, httplib::Response& res, const assets::File& file) {
  const std::string etag = etag_of(file.data);
  res.set_header("ETag", etag);
  res.set_header("Cache-Control", "no-cache");  // revalidated at every load: a new binary may have a new page
  if (req.get_header_value("If-None-Match") == etag) {
    res.status = 304;
    return;
  }
  res.status = 200;
  res.set_content(std::string(file.data), std::string(file.content_type));
}

void handle_root(RouteContext&, const Request& req, Response& res) {
  res.set_header("Vary", "Accept");
  // A browser asks for HTML and gets the page; an API client (curl, the Python client) gets the links.
  if (req.get_header_value("Accept").find("text/html") != std::string::npos) {
    if (const auto* page = find(assets::web_files(), "/web/index.html")) {
      res.set_header("Content-Security-Policy", kContentSecurityPolicy);
      res.set_header("Referrer-Policy", "no-referrer");
      send_file(req, res, *page);
      return;
    }
  }
  send_json(res, 200,
            {{"service", "contactd"},
             {"version", contact::solver_version()},
             {"links",
              {{"page", "/"},
               {"jobs", "/v1/jobs"},
               {"validate", "/v1/validate"},
               {"examples", "/v1/examples"},
               {"schema", "/v1/schema"},
               {"openapi", "/v1/openapi.yaml"},
               {"health", "/healthz"},
               {"ready", "/readyz"},
               {"metrics", "/metrics"}}}});
}

void handle_web_file(RouteContext&, const Request& req, Response& res) {
  const auto* file = find(assets::web_files(), req.path);
  if (!file) {
    send_problem(res, 404, "", "no such file of the web page: " + clip(req.path), req.path);
    return;
  }
  if (req.path == "/web/index.html") {
    // The page is at "/" (its links are relative to it).
    res.status = 302;
    res.set_header("Location", "../");
    return;
  }
  send_file(req, res, *file);
}

void handle_examples(RouteContext&, const Request&, Response& res) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& e : served_examples()) {
    const std::string name(e.name);
    list.push_back({{"name", name}, {"bytes", e.data.size()}, {"href", "/v1/examples/" + name}});
  }
  send_json(res, 200, {{"examples", list}});
}

void handle_example(RouteContext&, const Request& req, Response& res) {
  std::string name = req.matches[1];
  const auto* file = find(served_examples(), name);
  if (!file) {
    send_problem(res, 404, "", "no example '" + clip(name, 64) + "'; GET /v1/examples lists them", req.path);
    return;
  }
  send_file(req, res, *file);
}

}  // namespace

void register_web_routes(Router& router, RouteContext& ctx) {
  auto get = [&](const std::string& pattern, void (*handler)(RouteContext&, const Request&, Response&)) {
    router.get(pattern, [&ctx, handler](const Request& req, Response& res) { handler(ctx, req, res); });
  };
  get("/", handle_root);
  get(R"(/web/[A-Za-z0-9_./-]+)", handle_web_file);
  get("/v1/examples", handle_examples);
  get(R"(/v1/examples/([A-Za-z0-9_-]{1,64})(?:\.json)?)", handle_example);
}

}  // namespace contactd
