#include "read.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <limits>
#include <sstream>

namespace contact::job::read {

std::string escape_token(const std::string& token) {
  std::string out;
  out.reserve(token.size());
  for (char ch : token) {
    if (ch == '~')
      out += "~0";
    else if (ch == '/')
      out += "~1";
    else
      out += ch;
  }
  return out;
}

std::string child(const std::string& pointer, const std::string& key) { return pointer + "/" + escape_token(key); }

std::string child(const std::string& pointer, size_t index) { return pointer + "/" + std::to_string(index); }

std::string format_number(double value) {
  std::ostringstream os;
  if (std::isfinite(value) && value == std::floor(value) && std::abs(value) < 1e15)
    os << std::fixed << std::setprecision(0) << value;
  else
    os << std::setprecision(10) << value;
  return os.str();
}

std::string join_names(const std::vector<std::string>& names) {
  if (names.empty()) return "(none)";
  std::string out;
  for (size_t k = 0; k < names.size(); ++k) {
    if (k > 0) out += (k + 1 == names.size()) ? " and " : ", ";
    out += names[k];
  }
  return out;
}

std::string type_name(const json& value) { return value.type_name(); }

namespace {
// The first `max` bytes of `text`, cut back to a UTF-8 character boundary.
std::string utf8_prefix(const std::string& text, size_t max) {
  if (text.size() <= max) return text;
  size_t end = max;
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  return text.substr(0, end);
}
}  // namespace

namespace {
// The code point of the control character (U+0000-U+001F, U+007F-U+009F) at byte `k` of UTF-8 text and its
// length in bytes, or length 0 when there is none there.
std::pair<unsigned, size_t> control_at(const std::string& text, size_t k) {
  const auto c = static_cast<unsigned char>(text[k]);
  if (c < 0x20 || c == 0x7F) return {c, 1};
  const auto next = k + 1 < text.size() ? static_cast<unsigned char>(text[k + 1]) : 0u;
  if (c == 0xC2 && next >= 0x80 && next <= 0x9F) return {next, 2};
  return {0, 0};
}

// The code point of the invisible character at byte `k` of UTF-8 text (the zero-width and direction marks
// U+200B-U+200F, the bidirectional embeddings and overrides U+202A-U+202E, the isolates U+2066-U+2069, the
// zero-width no-break space U+FEFF) and its length in bytes (3), or length 0 when there is none there. They
// show as nothing, or reorder the text around them: a name holding one reads as another name.
std::pair<unsigned, size_t> invisible_at(const std::string& text, size_t k) {
  if (k + 2 >= text.size()) return {0, 0};
  const auto b0 = static_cast<unsigned char>(text[k]), b1 = static_cast<unsigned char>(text[k + 1]),
             b2 = static_cast<unsigned char>(text[k + 2]);
  if ((b0 & 0xF0) != 0xE0 || (b1 & 0xC0) != 0x80 || (b2 & 0xC0) != 0x80) return {0, 0};
  const unsigned code = ((b0 & 0x0Fu) << 12) | ((b1 & 0x3Fu) << 6) | (b2 & 0x3Fu);
  const bool invisible = (code >= 0x200B && code <= 0x200F) || (code >= 0x202A && code <= 0x202E) ||
                         (code >= 0x2066 && code <= 0x2069) || code == 0xFEFF;
  return invisible ? std::pair<unsigned, size_t>{code, 3} : std::pair<unsigned, size_t>{0, 0};
}

// A control or an invisible character at byte `k`: its code point and length, or length 0.
std::pair<unsigned, size_t> unprintable_at(const std::string& text, size_t k) {
  const auto control = control_at(text, k);
  return control.second > 0 ? control : invisible_at(text, k);
}

std::string code_point(unsigned code, const char* format) {
  char buffer[12];
  std::snprintf(buffer, sizeof buffer, format, code);
  return buffer;
}

// The text with each control or invisible character written \uXXXX, so that a message shows it rather than
// obeys it (an escape sequence driving the terminal, an override reordering the message).
std::string escape_controls(const std::string& text) {
  std::string out;
  for (size_t k = 0; k < text.size(); ++k) {
    const auto [code, length] = unprintable_at(text, k);
    if (length == 0) {
      out += text[k];
      continue;
    }
    out += code_point(code, "\\u%04X");
    k += length - 1;
  }
  return out;
}
}  // namespace

std::string shown(const std::string& text, size_t max) {
  if (text.size() <= max) return escape_controls(text);
  return escape_controls(utf8_prefix(text, max)) + "... (" + std::to_string(text.size()) + " bytes)";
}

namespace {
const char* const kUnprintableRule =
    "no control characters (U+0000 to U+001F, U+007F to U+009F), and no zero-width or bidirectional-control "
    "characters (U+200B to U+200F, U+202A to U+202E, U+2066 to U+2069, U+FEFF), which hide or reorder text";

// "the control character U+001B at byte 4" or "the invisible character U+202E at byte 1": the first character
// of `s` that is not printable text, or nullopt.
std::optional<std::string> first_unprintable(const std::string& s) {
  for (size_t k = 0; k < s.size(); ++k) {
    const auto [code, length] = unprintable_at(s, k);
    if (length == 0) continue;
    const char* kind = control_at(s, k).second > 0 ? "the control character " : "the invisible character ";
    return kind + code_point(code, "U+%04X") + " at byte " + std::to_string(k);
  }
  return std::nullopt;
}
}  // namespace

std::optional<std::string> control_character_problem(const std::string& s, const std::string& what) {
  if (auto found = first_unprintable(s))
    return what + " '" + shown(s) + "' contains " + *found + ": it must be printable text (" + kUnprintableRule + ")";
  return std::nullopt;
}

void Errors::add(std::string pointer, std::string message) {
  ++total_;
  if (list_.size() >= kMaxErrors) return;
  if (pointer.size() > kMaxErrorText) pointer = utf8_prefix(pointer, kMaxErrorText) + "...";
  if (message.size() > kMaxErrorText) message = utf8_prefix(message, kMaxErrorText) + "...";
  list_.push_back({std::move(pointer), std::move(message)});
}

std::vector<ValidationError> Errors::take() {
  std::vector<ValidationError> out = std::move(list_);
  if (total_ > out.size())
    out.push_back({"", "and " + std::to_string(total_ - out.size()) + " more errors (only the first " +
                           std::to_string(out.size()) + " are listed)"});
  list_.clear();
  total_ = 0;
  return out;
}

size_t Errors::count_under(const std::string& pointer) const {
  const auto n = static_cast<size_t>(std::count_if(list_.begin(), list_.end(), [&](const ValidationError& e) {
    return e.pointer == pointer || e.pointer.rfind(pointer + "/", 0) == 0;
  }));
  return total_ > list_.size() ? std::max<size_t>(n, 1) : n;
}

std::optional<double> number(const json& value, const std::string& pointer, const std::string& what, Errors& errors) {
  if (!value.is_number()) {
    errors.add(pointer, what + " must be a number, got " + type_name(value));
    return std::nullopt;
  }
  const double x = value.get<double>();
  if (!std::isfinite(x)) {
    errors.add(pointer, what + " must be a finite number (this one overflows a double)");
    return std::nullopt;
  }
  // Finite but huge values (1e308) overflow the stiffness matrices and every product after them: no physical
  // input in any unit system comes near this bound.
  if (std::abs(x) > kMaxMagnitude) {
    std::ostringstream os;
    os << what << " = " << x << " is too large in magnitude (at most " << kMaxMagnitude << ")";
    errors.add(pointer, os.str());
    return std::nullopt;
  }
  return x;
}

std::optional<long long> integer(const json& value, const std::string& pointer, const std::string& what,
                                 Errors& errors) {
  if (value.is_number_integer()) {
    // An unsigned value above the signed range is still far beyond any count the solver could use.
    if (value.is_number_unsigned() &&
        value.get<unsigned long long>() > static_cast<unsigned long long>(std::numeric_limits<long long>::max())) {
      errors.add(pointer, what + " = " + value.dump() + " is too large");
      return std::nullopt;
    }
    return value.get<long long>();
  }
  const auto x = number(value, pointer, what, errors);
  if (!x) return std::nullopt;
  if (*x != std::floor(*x)) {
    errors.add(pointer, what + " must be an integer, got " + format_number(*x));
    return std::nullopt;
  }
  if (std::abs(*x) >= 9.2e18) {
    errors.add(pointer, what + " = " + format_number(*x) + " is too large");
    return std::nullopt;
  }
  return static_cast<long long>(*x);
}

std::optional<std::string> string(const json& value, const std::string& pointer, const std::string& what,
                                  Errors& errors) {
  if (!value.is_string()) {
    errors.add(pointer, what + " must be a string, got " + type_name(value));
    return std::nullopt;
  }
  return value.get<std::string>();
}

std::optional<bool> boolean(const json& value, const std::string& pointer, const std::string& what, Errors& errors) {
  if (!value.is_boolean()) {
    errors.add(pointer, what + " must be true or false, got " + type_name(value));
    return std::nullopt;
  }
  return value.get<bool>();
}

std::optional<Eigen::Vector2d> pair(const json& value, const std::string& pointer, const std::string& what,
                                    Errors& errors) {
  if (!value.is_array() || value.size() != 2) {
    errors.add(pointer, what + " must be an array of two numbers [x, y], got " +
                            (value.is_array() ? "an array of " + std::to_string(value.size()) : type_name(value)));
    return std::nullopt;
  }
  const auto x = number(value[0], child(pointer, 0), what + " x", errors);
  const auto y = number(value[1], child(pointer, 1), what + " y", errors);
  if (!x || !y) return std::nullopt;
  return Eigen::Vector2d(*x, *y);
}

namespace {
// Levenshtein distance, for "did you mean" suggestions on unknown fields.
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}
}  // namespace

Fields::Fields(const json& value, std::string pointer, std::string what, std::vector<std::string> allowed,
               Errors& errors)
    : pointer_(std::move(pointer)), errors_(errors) {
  if (!value.is_object()) {
    errors_.add(pointer_, what + " must be an object, got " + type_name(value));
    return;
  }
  object_ = &value;
  for (const auto& item : value.items()) {
    if (std::find(allowed.begin(), allowed.end(), item.key()) != allowed.end()) continue;
    std::string message = "unknown field '" + shown(item.key()) + "' in " + what;
    std::string closest;
    size_t best = 3;  // suggest only close misspellings
    for (const auto& name : allowed) {
      // Lengths 3 or more apart are never a close misspelling (and a huge key costs nothing).
      const size_t longer = std::max(item.key().size(), name.size()),
                   shorter = std::min(item.key().size(), name.size());
      if (longer - shorter >= best) continue;
      const size_t d = edit_distance(item.key(), name);
      if (d < best) {
        best = d;
        closest = name;
      }
    }
    if (!closest.empty()) message += " (did you mean '" + closest + "'?)";
    message += "; allowed: " + join_names(allowed);
    errors_.add(child(pointer_, item.key()), message);
  }
}

const json* Fields::find(const std::string& key) const {
  if (!object_) return nullptr;
  auto it = object_->find(key);
  return it == object_->end() ? nullptr : &*it;
}

const json* Fields::require(const std::string& key, const std::string& hint) const {
  const json* value = find(key);
  if (!value && object_) errors_.add(at(key), "required field '" + key + "' is missing: " + hint);
  return value;
}

namespace {
// Letters, digits, '_' and '-' (and '.' when `dot`), at least one. A plain loop: std::regex_match recurses once
// per character and overflows the stack on a long name.
bool is_identifier(const std::string& s, bool dot = false) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [dot](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
           (dot && c == '.');
  });
}
}  // namespace

std::optional<std::string> name_problem(const std::string& s, const std::string& what, size_t max_length, bool dot) {
  const char* allowed = dot ? "letters, digits, '_', '-' and '.' only, and not '.' or '..' (pattern "
                              "^(?!\\.{1,2}$)[A-Za-z0-9_.-]+$)"
                            : "letters, digits, '_' and '-' only (pattern ^[A-Za-z0-9_-]+$)";
  if (s.size() > max_length)
    return what + " '" + read::shown(s) + "' is too long: at most " + std::to_string(max_length) + " characters";
  if (!is_identifier(s, dot)) {
    // A control or invisible character is named by its code point: it cannot be seen in the name quoted.
    const auto found = first_unprintable(s);
    return what + " '" + read::shown(s) + "' must consist of " + allowed +
           (found ? "; it contains " + *found + ", which is not printable text (" + kUnprintableRule + ")" : "");
  }
  // "." and "..": a path's components, not names (the result file would take them for its own groups).
  if (s == "." || s == "..")
    return what + " '" + s +
           "' is not a name: '.' and '..' mean this and the parent group in the result file; a "
           "name must consist of " +
           allowed;
  return std::nullopt;
}

std::optional<std::string> identifier(const json& value, const std::string& pointer, const std::string& what,
                                      size_t max_length, Errors& errors) {
  auto s = read::string(value, pointer, what, errors);
  if (!s) return std::nullopt;
  if (auto problem = name_problem(*s, what, max_length, false)) {
    errors.add(pointer, *problem);
    return std::nullopt;
  }
  return s;
}

std::optional<double> positive(const json& value, const std::string& pointer, const std::string& what, Errors& errors) {
  auto x = read::number(value, pointer, what, errors);
  if (x && !(*x > 0)) {
    errors.add(pointer, what + " = " + format_number(*x) + " must be positive");
    return std::nullopt;
  }
  return x;
}

std::optional<std::string> choice(const json& value, const std::string& pointer, const std::string& what,
                                  const std::vector<std::string>& options, Errors& errors) {
  auto s = read::string(value, pointer, what, errors);
  if (!s) return std::nullopt;
  if (std::find(options.begin(), options.end(), *s) == options.end()) {
    std::vector<std::string> quoted;
    for (const auto& o : options) quoted.push_back("\"" + o + "\"");
    errors.add(pointer, what + " \"" + read::shown(*s) + "\" is not one of " + join_names(quoted));
    return std::nullopt;
  }
  return s;
}

std::optional<int> bounded_int(const json& value, const std::string& pointer, const std::string& what, long long min,
                               Errors& errors, long long max) {
  auto n = read::integer(value, pointer, what, errors);
  if (!n) return std::nullopt;
  if (*n < min) {
    errors.add(pointer, what + " = " + std::to_string(*n) + " must be at least " + std::to_string(min));
    return std::nullopt;
  }
  if (*n > max) {
    errors.add(pointer, what + " = " + std::to_string(*n) + " is too large (at most " + std::to_string(max) + ")");
    return std::nullopt;
  }
  return static_cast<int>(*n);
}

}  // namespace contact::job::read
