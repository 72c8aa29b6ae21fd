// The job format's names of the settings' choices, one table per enumeration (problem.hpp): the reader checks a
// given name against its table and takes the value from it, and writes a default's name from it, so a name is
// spelt once. Method and Enforcement have their tables in solver/problem.cpp (the result and the progress give
// those names back too). Private to the job module.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "contact/problem.hpp"
#include "read.hpp"

namespace contact::job::detail {

// NameTable<E>::entries: each value with its name, in the order the messages list them.
template <typename E>
struct NameTable;

template <typename E, std::size_t N>
using Entries = std::array<std::pair<E, const char*>, N>;

template <>
struct NameTable<Plane> {
  static constexpr Entries<Plane, 2> entries{{{Plane::strain, "strain"}, {Plane::stress, "stress"}}};
};
template <>
struct NameTable<Criterion> {
  static constexpr Entries<Criterion, 2> entries{{{Criterion::paper, "paper"}, {Criterion::residual, "residual"}}};
};
template <>
struct NameTable<InitialGuess> {
  static constexpr Entries<InitialGuess, 2> entries{
      {{InitialGuess::zero, "zero"}, {InitialGuess::elastic_layer, "elastic_layer"}}};
};
template <>
struct NameTable<Acceleration> {
  static constexpr Entries<Acceleration, 2> entries{
      {{Acceleration::none, "none"}, {Acceleration::anderson, "anderson"}}};
};
template <>
struct NameTable<InterfaceSolverKind> {
  static constexpr Entries<InterfaceSolverKind, 3> entries{{{InterfaceSolverKind::automatic, "auto"},
                                                            {InterfaceSolverKind::direct, "direct"},
                                                            {InterfaceSolverKind::iterative, "iterative"}}};
};
template <>
struct NameTable<InterfacePreconditioner> {
  static constexpr Entries<InterfacePreconditioner, 4> entries{{{InterfacePreconditioner::automatic, "auto"},
                                                                {InterfacePreconditioner::none, "none"},
                                                                {InterfacePreconditioner::lumped, "lumped"},
                                                                {InterfacePreconditioner::dirichlet, "dirichlet"}}};
};
template <>
struct NameTable<Indicator> {
  static constexpr Entries<Indicator, 2> entries{{{Indicator::fem_bem, "fem_bem"}, {Indicator::zz, "zz"}}};
};
template <>
struct NameTable<Normalization> {
  static constexpr Entries<Normalization, 2> entries{{{Normalization::rms, "rms"}, {Normalization::area, "area"}}};
};
template <>
struct NameTable<MarkingRule> {
  static constexpr Entries<MarkingRule, 3> entries{
      {{MarkingRule::contact, "contact"}, {MarkingRule::plain, "plain"}, {MarkingRule::goal, "goal"}}};
};
template <>
struct NameTable<AdaptStrategy> {
  static constexpr Entries<AdaptStrategy, 2> entries{
      {{AdaptStrategy::paper, "paper"}, {AdaptStrategy::converge_then_refine, "converge_then_refine"}}};
};
template <>
struct NameTable<Fit> {
  static constexpr Entries<Fit, 3> entries{
      {{Fit::touching, "touching"}, {Fit::interference, "interference"}, {Fit::clearance, "clearance"}}};
};
template <>
struct NameTable<StepOutput> {  // "last" first, as the messages have always listed them
  static constexpr Entries<StepOutput, 2> entries{{{StepOutput::last, "last"}, {StepOutput::all, "all"}}};
};

// The name of a value (every value has one: the tables are complete).
template <typename E>
const char* name_of(E value) {
  for (const auto& [v, name] : NameTable<E>::entries)
    if (v == value) return name;
  return NameTable<E>::entries[0].second;
}

template <typename E>
std::vector<std::string> names_of() {
  std::vector<std::string> names;
  for (const auto& entry : NameTable<E>::entries) names.emplace_back(entry.second);
  return names;
}

// Reads one of E's names into `target`; a name not in the table is reported (read::choice) and leaves it.
template <typename E>
void read_name(const nlohmann::json& value, const std::string& pointer, const std::string& what, E& target,
               read::Errors& errors) {
  if (auto name = read::choice(value, pointer, what, names_of<E>(), errors))
    for (const auto& [v, text] : NameTable<E>::entries)
      if (*name == text) target = v;
}

}  // namespace contact::job::detail
