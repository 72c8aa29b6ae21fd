#include "contact/problem.hpp"

#include <array>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace contact {

namespace {

constexpr std::array<std::pair<Method, const char*>, 4> kMethods = {{{Method::neumann, "neumann"},
                                                                     {Method::monolithic, "monolithic"},
                                                                     {Method::interface_newton, "interface_newton"},
                                                                     {Method::robin, "robin"}}};
constexpr std::array<std::pair<Enforcement, const char*>, 3> kEnforcements = {
    {{Enforcement::exact, "exact"},
     {Enforcement::penalty, "penalty"},
     {Enforcement::augmented_lagrangian, "augmented_lagrangian"}}};

}  // namespace

const char* to_string(Method m) {
  for (const auto& [value, name] : kMethods)
    if (value == m) return name;
  return "interface_newton";
}

const char* to_string(Enforcement e) {
  for (const auto& [value, name] : kEnforcements)
    if (value == e) return name;
  return "exact";
}

std::optional<Method> method_named(const std::string& name) {
  for (const auto& [value, text] : kMethods)
    if (name == text) return value;
  return std::nullopt;
}

std::optional<Enforcement> enforcement_named(const std::string& name) {
  for (const auto& [value, text] : kEnforcements)
    if (name == text) return value;
  return std::nullopt;
}

std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for (const auto& entry : kMethods) names.emplace_back(entry.second);
  return names;
}

std::vector<std::string> enforcement_names() {
  std::vector<std::string> names;
  for (const auto& entry : kEnforcements) names.emplace_back(entry.second);
  return names;
}

bool iterates_on_penalty(Method method) { return method == Method::neumann || method == Method::robin; }

std::string settings_conflict(const SolverSettings& settings) {
  if (iterates_on_penalty(settings.method) && settings.enforcement == Enforcement::exact)
    return std::string("method \"") + to_string(settings.method) +
           "\" iterates on the penalty problem: enforcement \"exact\" is not available with it (use \"penalty\", or "
           "\"augmented_lagrangian\" for exact contact in the limit, or method \"interface_newton\")";
  return {};
}

std::string friction_conflict(const SolverSettings& settings) {
  if (iterates_on_penalty(settings.method))
    return std::string("friction is solved on the interface problem (semismooth Newton on stick and slip): method \"") +
           to_string(settings.method) +
           "\" cannot take it; use method \"interface_newton\" (the default) or \"monolithic\"";
  if (settings.enforcement != Enforcement::exact)
    return std::string(
               "friction needs exact contact (enforcement \"exact\", the default of interface_newton), not \"") +
           to_string(settings.enforcement) + "\"";
  return {};
}

InterfaceMemoryEstimate estimate_interface_memory(const std::vector<ContactPair>& contacts, size_t bodies,
                                                  const std::function<double(int, const std::string&)>& edge_nodes) {
  std::map<std::pair<int, std::string>, double> nodes_of_edge;  // each contact edge's nodes, counted once
  const auto nodes_on = [&](int body, const std::string& edge) {
    auto [it, inserted] = nodes_of_edge.try_emplace({body, edge}, 0.0);
    if (inserted) it->second = edge_nodes(body, edge);
    return it->second;
  };
  std::set<std::pair<int, std::string>> counted;  // the edges whose unknowns are in `unknowns`
  std::vector<double> unknowns(bodies, 0.0), rows(bodies, 0.0);
  std::vector<char> friction(bodies, 0);
  for (const auto& c : contacts) {
    const double pair_rows = nodes_on(c.slave_body, c.slave_edge) * (c.friction.active() ? 2.0 : 1.0);
    for (const auto& [body, edge] :
         {std::make_pair(c.slave_body, c.slave_edge), std::make_pair(c.master_body, c.master_edge)}) {
      const auto b = static_cast<size_t>(body);
      if (b >= bodies) continue;
      rows[b] += pair_rows;
      friction[b] = friction[b] || c.friction.active();
      if (counted.insert({body, edge}).second) unknowns[b] += 2.0 * nodes_on(body, edge);
    }
  }
  InterfaceMemoryEstimate out;
  out.largest = -1.0;
  for (size_t b = 0; b < bodies; ++b) {
    const double z = unknowns[b], r = rows[b];
    const double body_bytes = 8.0 * (z * z + z * r + (friction[b] ? 6.0 : 3.0) * r * r);
    out.bytes += body_bytes;
    if (body_bytes > out.largest) {
      out.largest = body_bytes;
      out.body = b;
      out.contact_nodes = z / 2.0;
    }
  }
  out.largest = std::max(out.largest, 0.0);
  return out;
}

}  // namespace contact
