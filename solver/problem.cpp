#include "contact/problem.hpp"

#include <array>
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

}  // namespace contact
