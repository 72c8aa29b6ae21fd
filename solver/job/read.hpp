// Reading JSON values with validation: typed views of a value that report what is wrong with it at its
// RFC 6901 pointer instead of throwing. Private to the job module; the job reader (job_reader.hpp) holds the format.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "contact/job.hpp"

namespace contact::job::read {

using nlohmann::json;

// Documents nested deeper than this are rejected (a job needs 6 levels); it bounds the recursion of every
// later walk over the document, nlohmann's own copy and comparison included.
constexpr int kMaxDepth = 64;

// RFC 6901: "~" is written "~0" and "/" is written "~1" inside a reference token.
std::string escape_token(const std::string& token);
std::string child(const std::string& pointer, const std::string& key);
std::string child(const std::string& pointer, size_t index);

// Numbers in messages: integers exactly, others with up to 10 significant digits.
std::string format_number(double value);
// "a, b and c" for messages; "(none)" when empty.
std::string join_names(const std::vector<std::string>& names);
// nlohmann's type name: "object", "array", "string", "boolean", "number", "null".
std::string type_name(const json& value);

// A value from the job for a message: itself when short, else its first `max` bytes (whole UTF-8 characters)
// and how long it is, so that an error never echoes a huge input back; control characters written \u00XX.
std::string shown(const std::string& text, size_t max = 64);

// Why `s` (the `what` of the job, e.g. "name") is not printable text: the first control character it holds
// (U+0000-U+001F, U+007F-U+009F: a NUL cuts the name short in the result file, an escape sequence drives the
// terminal that prints it) or invisible character (zero-width U+200B-U+200F and U+FEFF, bidirectional controls
// U+202A-U+202E and U+2066-U+2069: they make a name in the job list or a download's file name read as another),
// or nullopt. The one rule for free text; names (name_problem) are stricter.
std::optional<std::string> control_character_problem(const std::string& s, const std::string& what);

// The errors found so far, in the order found. Each message and pointer is cut to kMaxErrorText bytes, and only
// the first kMaxErrors are kept (take() then adds one line saying how many more were found): a hostile document
// cannot make the error list larger than its own size.
class Errors {
 public:
  static constexpr size_t kMaxErrors = 200;
  static constexpr size_t kMaxErrorText = 1024;

  void add(std::string pointer, std::string message);
  // Every error found, kept or not.
  size_t size() const { return total_; }
  // How many errors point at `pointer` or inside it (at least 1 once errors were dropped: unknown, so assume some).
  size_t count_under(const std::string& pointer) const;
  const std::vector<ValidationError>& list() const { return list_; }
  std::vector<ValidationError> take();

 private:
  std::vector<ValidationError> list_;
  size_t total_ = 0;
};

// Typed views of one value. `what` names the value in messages ("nu", "corner 2"). Each returns nullopt after
// reporting the problem: wrong type ("nu must be a number, got string"), or a number that is not finite
// (nlohmann reads 1e400 as infinity) or, for integers, has a fractional part. 2.0 counts as an integer, as in
// JSON Schema.
// Largest magnitude accepted for any number of a job.
inline constexpr double kMaxMagnitude = 1e30;

std::optional<double> number(const json& value, const std::string& pointer, const std::string& what, Errors& errors);
std::optional<long long> integer(const json& value, const std::string& pointer, const std::string& what,
                                 Errors& errors);
std::optional<std::string> string(const json& value, const std::string& pointer, const std::string& what,
                                  Errors& errors);
std::optional<bool> boolean(const json& value, const std::string& pointer, const std::string& what, Errors& errors);
// A point or vector written [x, y].
std::optional<Eigen::Vector2d> pair(const json& value, const std::string& pointer, const std::string& what,
                                    Errors& errors);

// Values of the job's own kinds, read and reported the same way. Names that other parts of the job refer to
// (bodies, edges, vertices, contacts) consist of letters, digits, '_' and '-' (and '.' when `dot`), at least one;
// with dots, "." and ".." are not names (the result file's groups are named after them).
// Why `s` is not a name of at most `max_length` characters of the allowed set (the pattern quoted; a control or
// invisible character named by its code point), or nullopt. The one check of every name.
std::optional<std::string> name_problem(const std::string& s, const std::string& what, size_t max_length, bool dot);
// Reads a name that other parts of the job refer to ("body.edge"), so it must be an identifier.
std::optional<std::string> identifier(const json& value, const std::string& pointer, const std::string& what,
                                      size_t max_length, Errors& errors);
// A number that must be > 0.
std::optional<double> positive(const json& value, const std::string& pointer, const std::string& what, Errors& errors);
// One of a fixed set of strings.
std::optional<std::string> choice(const json& value, const std::string& pointer, const std::string& what,
                                  const std::vector<std::string>& options, Errors& errors);
// An integer in [min, max]; `max` defaults to what an int holds.
std::optional<int> bounded_int(const json& value, const std::string& pointer, const std::string& what, long long min,
                               Errors& errors, long long max = std::numeric_limits<int>::max());

// The fields of one JSON object. Construction reports a value that is not an object and every field not in
// `allowed` (unknown fields are errors: a misspelt optional field must not be silently ignored).
class Fields {
 public:
  Fields(const json& value, std::string pointer, std::string what, std::vector<std::string> allowed, Errors& errors);

  bool ok() const { return object_ != nullptr; }
  const std::string& pointer() const { return pointer_; }
  std::string at(const std::string& key) const { return child(pointer_, key); }
  bool has(const std::string& key) const { return find(key) != nullptr; }
  // nullptr if absent (or if the value is not an object).
  const json* find(const std::string& key) const;
  // As find, and reports a missing field at the pointer where it belongs; `hint` says what it should hold.
  const json* require(const std::string& key, const std::string& hint) const;

 private:
  const json* object_ = nullptr;
  std::string pointer_;
  Errors& errors_;
};

}  // namespace contact::job::read
