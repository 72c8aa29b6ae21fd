// The files contactd serves from its own binary, so that it needs no source tree at run time: the job schema, the
// API spec, the web page (server/web/, with its vendored plotting library) and the example jobs (api/examples/).
// Generated at build time by server/embed_assets.cmake (embedded_assets.cpp in the build directory).
#pragma once

#include <string_view>
#include <vector>

namespace contactd::assets {

struct File {
  std::string_view name;          // web files: the URL path ("/web/app.js"); examples: "seed_layers"
  std::string_view content_type;  // "text/javascript; charset=utf-8", ...
  std::string_view data;
};

std::string_view job_schema();              // api/job.schema.json
std::string_view openapi_yaml();            // api/openapi.yaml
const std::vector<File>& web_files();       // server/web/**, sorted by name
const std::vector<File>& examples();        // api/examples/*.json, sorted by name
const std::vector<File>& example_meshes();  // api/examples/*.msh by file name ("punch_rounded_gmsh.msh")

}  // namespace contactd::assets
