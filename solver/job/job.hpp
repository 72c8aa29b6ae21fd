// JSON contact job -> Problem, with validation. Every problem found is reported (not only the first), each
// with the RFC 6901 JSON pointer of the offending value and a sentence saying what is wrong.
#pragma once

#include "../problem.hpp"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace contact::job {

struct ValidationError {
  std::string pointer;  // e.g. "/bodies/1/material/nu"; "" for the document itself
  std::string message;  // e.g. "nu = 0.5 is outside (-1, 0.5)"
};

struct Limits {
  long max_dofs = 2'000'000;  // total over all bodies; larger jobs are rejected, not attempted
};

struct ParseResult {
  std::optional<Problem> problem;  // set if and only if errors is empty
  std::vector<ValidationError> errors;
  bool ok() const { return errors.empty(); }
};

// Validates a parsed JSON document and builds the Problem (meshes generated, defaults filled in,
// Problem::submitted and Problem::normalized set). Never throws for bad input.
ParseResult parse(const nlohmann::json& job, const Limits& limits = {});

// Same from text; malformed JSON gives one error with pointer "" naming the byte offset.
ParseResult parse_text(const std::string& text, const Limits& limits = {});

// One line per error: "<pointer>: <message>".
std::string format_errors(const std::vector<ValidationError>& errors);

}  // namespace contact::job
