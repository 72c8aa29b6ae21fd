// The HTTP server's settings (contactd's command line and environment: docs/server.md).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace contactd {

struct HttpSettings {
  std::string host = "127.0.0.1";
  int port = 8080;                           // 0: any free port (bind() returns it)
  std::size_t max_request_bytes = 8u << 20;  // larger bodies get 413
  std::string token;                         // "" = no authentication
  int heartbeat_seconds = 15;                // SSE comment / NDJSON empty line at least this often
  int max_streams = 64;                      // concurrent progress streams; more get 503
  int http_threads = 0;                      // 0 = max_streams + 32
  bool access_log = false;                   // one stderr line per request
  std::vector<std::string> allowed_hosts;    // Host header allow-list; empty = loopback names and `host`
  // Connections (connection_gate.hpp).
  std::size_t max_connections = 1024;
  std::size_t max_connections_per_client = 512;
  int listen_backlog = 1024;
  double head_timeout_seconds = 10.0;
  double idle_timeout_seconds = 5.0;
  double body_timeout_seconds = 60.0;
  std::size_t max_header_bytes = 16 * 1024;
  std::size_t max_header_fields = 64;
  // Job bodies (body_budget.hpp).
  std::size_t max_large_bodies = 4;  // bodies over 256 KiB read at once
  std::size_t max_validations = 0;   // jobs parsed and validated at once; 0 = the number of cores (at least 2)
};

}  // namespace contactd
