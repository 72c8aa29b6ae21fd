#include "http/routes.hpp"

#include <algorithm>

namespace contactd {

void Router::get(const std::string& pattern, Handler handler) {
  routes_.push_back({"GET", std::regex(pattern)});
  core_.Get(pattern, std::move(handler));
}

void Router::post(const std::string& pattern, Handler handler) {
  routes_.push_back({"POST", std::regex(pattern)});
  core_.Post(pattern, std::move(handler));
}

void Router::post_body(const std::string& pattern, BodyHandler handler) {
  routes_.push_back({"POST", std::regex(pattern)});
  core_.Post(pattern, std::move(handler));
}

void Router::del(const std::string& pattern, Handler handler) {
  routes_.push_back({"DELETE", std::regex(pattern)});
  core_.Delete(pattern, std::move(handler));
}

bool Router::known(const std::string& method, const std::string& path) const {
  return std::any_of(routes_.begin(), routes_.end(), [&](const Route& route) {
    return route.method == method && std::regex_match(path, route.pattern);
  });
}

std::vector<std::string> Router::allowed(const std::string& path) const {
  std::vector<std::string> out;
  for (const auto& route : routes_)
    if (std::regex_match(path, route.pattern) && std::find(out.begin(), out.end(), route.method) == out.end())
      out.push_back(route.method);
  return out;
}

}  // namespace contactd
