// The checks every request passes before routing (called by the pre-routing handler), each a pure function of
// the request: header syntax httplib does not check, the Host allow-list (DNS rebinding), and the rules that keep
// a web page of another site from changing state (cross-site request forgery). And the small header helpers the
// handlers share.
#pragma once

#include <httplib.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace contactd {

struct GuardSettings {
  // Host names (without port) a request's Host header may name; "*" allows any. Compared case-insensitively;
  // IPv6 addresses in brackets ("[::1]").
  std::vector<std::string> allowed_hosts = {"localhost", "127.0.0.1", "[::1]"};
  bool token_required = false;
};

// Why a request is refused: its status, problem type slug ("" = about:blank) and detail.
struct Refusal {
  int status;
  std::string slug;
  std::string detail;
};

// Duplicate or malformed Content-Length, Content-Length with Transfer-Encoding, a transfer coding other than
// chunked (RFC 9112 6.1-6.3: request smuggling); a Host header missing in HTTP/1.1 or given twice.
std::optional<Refusal> check_framing(const httplib::Request& req);

// The Host header must name an allowed host (421 otherwise).
std::optional<Refusal> check_host(const httplib::Request& req, const GuardSettings& settings);

// POST and DELETE under /v1: an Origin header, if any, must name an allowed host, and a request without a body
// must carry Content-Type: application/json or an X-Requested-With header (403 otherwise); a body must be JSON
// anyway (415). A page of another site can send none of these without a CORS preflight, which contactd never
// grants.
std::optional<Refusal> check_cross_site(const httplib::Request& req, const GuardSettings& settings);

// Splits "--allowed-hosts" text ("a, b,c") into names, lower case.
std::vector<std::string> parse_host_list(const std::string& text);

// A decimal integer in [0, max]; false for anything else (signs, spaces, overflow, empty).
bool parse_count(const std::string& text, std::uint64_t max, std::uint64_t& value);
std::string lower(std::string s);
std::string trim(const std::string& s);
// The media type of a Content-Type value, lower case, without parameters.
std::string media_type(const std::string& content_type);
// The request announces a body (chunked, or a Content-Length other than 0).
bool has_body(const httplib::Request& req);

}  // namespace contactd
