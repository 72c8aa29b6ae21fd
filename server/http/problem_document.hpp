// RFC 9457 problem documents: the problem types this API defines (GET /problems/<slug> explains each), the
// reason phrases of HTTP statuses, and the functions that answer with a JSON body. Every 4xx/5xx of contactd,
// including those the connection gate writes itself, goes through problem_document().
#pragma once

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>

namespace contactd {

struct ProblemType {
  const char* slug;
  const char* title;
  const char* description;
};

// Every problem type of the API, for GET /problems/<slug>; nullptr past the end.
const ProblemType* problem_types();
std::size_t problem_type_count();

// The reason phrase of a status (RFC 9110), the title of an about:blank problem.
const char* reason_phrase(int status);

// `text` cut to at most `max` bytes at a UTF-8 character boundary, with "..." when cut: what the server echoes
// of a request is bounded.
std::string clip(const std::string& text, std::size_t max = 256);

// JSON text; invalid UTF-8 (a hostile path echoed in `instance`) is replaced instead of throwing.
std::string dump(const nlohmann::json& j);

// The problem document as text. `slug` names one of the problem types, or is "" for about:blank; `detail` and
// `instance` are clipped to 1 KiB.
std::string problem_document(int status, const std::string& slug, const std::string& detail,
                             const std::string& instance, nlohmann::json extra = nlohmann::json::object());

void send_json(httplib::Response& res, int status, const nlohmann::json& j);
void send_problem(httplib::Response& res, int status, const std::string& slug, const std::string& detail,
                  const std::string& instance, nlohmann::json extra = nlohmann::json::object());

}  // namespace contactd
