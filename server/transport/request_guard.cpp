#include "transport/request_guard.hpp"

#include "http/problem_document.hpp"

#include <algorithm>
#include <cctype>

namespace contactd {

bool parse_count(const std::string& text, std::uint64_t max, std::uint64_t& value) {
  if (text.empty() || text.size() > 19) return false;
  value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
    value = value * 10 + static_cast<std::uint64_t>(c - '0');
  }
  return value <= max;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::string media_type(const std::string& content_type) {
  return lower(trim(content_type.substr(0, content_type.find(';'))));
}

bool has_body(const httplib::Request& req) {
  return req.has_header("Transfer-Encoding") ||
         (req.has_header("Content-Length") && req.get_header_value("Content-Length") != "0");
}

std::vector<std::string> parse_host_list(const std::string& text) {
  std::vector<std::string> hosts;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    std::string host = lower(trim(text.substr(start, comma - start)));
    if (!host.empty()) hosts.push_back(host);
    start = comma + 1;
  }
  return hosts;
}

namespace {

// The host of a Host header value or of an authority: "[::1]:8080" -> "[::1]", "Example.org:80" -> "example.org";
// nullopt when what follows the host is not ":" and a port (RFC 9110 7.2: Host = uri-host [ ":" port ], port =
// *DIGIT), as in "127.0.0.1:80:evil" or "[::1]x": such a value names no host at all.
std::optional<std::string> host_part(const std::string& authority) {
  std::string host = lower(trim(authority)), port;
  if (!host.empty() && host[0] == '[') {
    const auto close = host.find(']');
    if (close == std::string::npos) return std::nullopt;
    port = host.substr(close + 1);
    host = host.substr(0, close + 1);
  } else if (const auto colon = host.find(':'); colon != std::string::npos) {
    port = host.substr(colon);
    host = host.substr(0, colon);
  }
  if (!port.empty() && (port[0] != ':' || port.size() > 6 ||
                        !std::all_of(port.begin() + 1, port.end(), [](char c) { return c >= '0' && c <= '9'; })))
    return std::nullopt;
  if (!host.empty() && host.back() == '.') host.pop_back();  // "localhost." is "localhost"
  return host;
}

bool allowed(const std::string& host, const GuardSettings& settings) {
  return std::any_of(settings.allowed_hosts.begin(), settings.allowed_hosts.end(),
                     [&](const std::string& a) { return a == "*" || a == host; });
}

std::string allowed_list(const GuardSettings& settings) {
  std::string out;
  for (const auto& h : settings.allowed_hosts) out += (out.empty() ? "" : ", ") + h;
  return out;
}

}  // namespace

std::optional<Refusal> check_framing(const httplib::Request& req) {
  const std::size_t lengths = req.get_header_value_count("Content-Length");
  if (lengths > 0) {
    const std::string first = trim(req.get_header_value("Content-Length", 0));
    for (std::size_t k = 1; k < lengths; ++k)
      if (trim(req.get_header_value("Content-Length", k)) != first)
        return Refusal{400, "invalid-request", "the request has several Content-Length headers that differ"};
    std::uint64_t length = 0;
    if (first.find(',') != std::string::npos || !parse_count(first, UINT64_MAX / 2, length))
      return Refusal{400, "invalid-request", "the Content-Length header is not a number"};
  }
  if (req.has_header("Transfer-Encoding")) {
    if (lengths > 0)
      return Refusal{400, "invalid-request", "the request has both Content-Length and Transfer-Encoding"};
    if (req.get_header_value_count("Transfer-Encoding") > 1 ||
        lower(trim(req.get_header_value("Transfer-Encoding"))) != "chunked")
      return Refusal{501, "", "the only transfer coding accepted is chunked"};
  }
  if (req.get_header_value_count("Host") > 1)
    return Refusal{400, "invalid-request", "the request has two Host headers"};
  if (req.version == "HTTP/1.1" && !req.has_header("Host"))
    return Refusal{400, "invalid-request", "an HTTP/1.1 request needs a Host header"};
  return std::nullopt;
}

std::optional<Refusal> check_host(const httplib::Request& req, const GuardSettings& settings) {
  if (!req.has_header("Host")) return std::nullopt;  // HTTP/1.0 (browsers always send one)
  const std::optional<std::string> parsed = host_part(req.get_header_value("Host"));
  if (!parsed)
    return Refusal{
        400, "invalid-request",
        "the Host header '" + clip(req.get_header_value("Host"), 100) + "' is not a host and an optional port"};
  const std::string& host = *parsed;
  if (allowed(host, settings)) return std::nullopt;
  return Refusal{421, "host-not-allowed",
                 "this server does not serve the host '" + clip(host, 100) + "' (allowed: " + allowed_list(settings) +
                     "; set --allowed-hosts)"};
}

std::optional<Refusal> check_cross_site(const httplib::Request& req, const GuardSettings& settings) {
  const bool api = req.path == "/v1" || req.path.rfind("/v1/", 0) == 0;
  if (!api || (req.method != "POST" && req.method != "DELETE")) return std::nullopt;
  if (req.has_header("Origin")) {
    const std::string origin = lower(trim(req.get_header_value("Origin")));
    const auto scheme = origin.find("://");
    const std::string host =
        scheme == std::string::npos ? std::string() : host_part(origin.substr(scheme + 3)).value_or(std::string());
    if (host.empty() || !allowed(host, settings))
      return Refusal{403, "cross-site-request",
                     "requests from the origin '" + clip(origin, 100) +
                         "' may not change state here (allowed hosts: " + allowed_list(settings) + ")"};
  }
  // A body that is not JSON is refused with 415 before anything happens; a body-less POST or a DELETE proves
  // nothing by its content, so it needs one of the two headers.
  if (has_body(req) || media_type(req.get_header_value("Content-Type")) == "application/json") return std::nullopt;
  if (!trim(req.get_header_value("X-Requested-With")).empty()) return std::nullopt;
  return Refusal{403, "cross-site-request",
                 req.method +
                     " needs 'Content-Type: application/json' or an 'X-Requested-With' header (a web page of "
                     "another site cannot send either without the server's consent)"};
}

}  // namespace contactd
