// JSON contact job -> Problem, with validation. Every problem found is reported (not only the first), each
// with the RFC 6901 JSON pointer of the offending value and a sentence saying what is wrong.
#pragma once

#include "contact/problem.hpp"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace contact::job {

struct ValidationError {
  std::string pointer;  // e.g. "/bodies/1/material/nu"; "" for the document itself
  std::string message;  // e.g. "nu = 0.5 is outside (-1, 0.5)"
};

// Upper bounds on every field that sets the work or the resources a job takes (docs/job-format.md, "Limits").
// A job over any of them is rejected with an error at the field's pointer, before anything is built.
struct Limits {
  long max_dofs = 2'000'000;  // total over all bodies; larger jobs are rejected, not attempted
  // Bodies and pairs: the iterative interface solver handles thousands (a 64 x 64 brick wall has 4,129 bodies and
  // 8,128 pairs); validation and pair set-up are linear in them. contactd sets its own (--max-bodies, --max-contacts).
  int max_bodies = 16384;
  int max_contacts = 65536;
  int max_threads = 64;          // solver.threads
  int max_iterations = 100'000;  // solver.max_iterations
  int max_updates = 1'000;       // solver.augmented_lagrangian.max_updates
  int max_adaptive_steps = 100;  // adaptivity.max_steps
  int max_load_steps = 1000;     // loading.steps, or the number of loading.factors
  // The result file's size (the disk a job takes; its steps are streamed to it as solved), as estimated before
  // the job runs (io::estimated_result_bytes: nodes x kept steps); 0: no limit (the command line), contactd's
  // --max-result-bytes otherwise.
  double max_result_bytes = 0;
  std::string result_bytes_hint;  // the setting named when a job is over max_result_bytes
  // The memory of the interface problem (method interface_newton: dense blocks over each body's contact unknowns
  // and its pairs' rows), as estimated from the contact edges' nodes before anything is factorised; 0: no limit.
  // A long contact made it grow with the square of its nodes (two strips of 16,000 elements: about 30 GB, an OOM
  // kill) far below max_dofs. contact-solve sets this machine's memory, contactd its --max-interface-bytes.
  double max_interface_bytes = 0;
  std::string interface_bytes_hint;  // the setting named when a job is over max_interface_bytes
  // Validation's own time (s; 0: none). Every check is linear or n log n in the job's size, so a job within the
  // other limits validates in a second or two; this bounds what a pathological one costs a server: past it the
  // reader stops at its next phase (or every 64 bodies or pairs) and refuses the job with the time it took.
  double max_validation_seconds = 0;
  std::string validation_seconds_hint;  // the setting named when validation runs out of time
  int max_ranks = 4096;                 // parallel.ranks (contactd: its --max-ranks, 1 without an MPI launcher)
  std::string ranks_hint;               // appended to the message when parallel.ranks is over max_ranks
  std::size_t max_name_length = 64;     // body, edge and contact names (identifiers)
  std::size_t max_job_name_length = 256;
  // Gmsh meshes given as {"file": ...} are read relative to this directory (the job file's: parse_file sets it).
  // Unset, a job may not name a file (the server: a job sends the .msh text as "data").
  std::optional<std::string> mesh_directory;
  std::size_t max_mesh_file_bytes = 256u << 20;  // a .msh file read from disk
  // Every job strict: its warnings are errors (contact-solve --strict; a job asks for it with "strict": true).
  bool strict = false;
};

struct ParseResult {
  std::optional<Problem> problem;  // set if and only if errors is empty
  std::vector<ValidationError> errors;
  // What the model checks found in a valid job (the same as problem->warnings; docs/job-format.md, "Warnings"): a
  // strict job has none here, they are among its errors.
  std::vector<Warning> warnings;
  bool ok() const { return errors.empty(); }
};

// Validates a parsed JSON document and builds the Problem (meshes generated, defaults filled in,
// Problem::submitted and Problem::normalized set). Never throws for bad input.
ParseResult parse(const nlohmann::json& job, const Limits& limits = {});

// Same from text; malformed JSON gives one error with pointer "" naming the byte offset.
ParseResult parse_text(const std::string& text, const Limits& limits = {});

// Same from a job file: its Gmsh mesh files are read relative to its directory (limits.mesh_directory is set to
// job_directory(path)). A job file that cannot be read gives one error with pointer "".
ParseResult parse_file(const std::string& path, Limits limits = {});

// The directory of the job file at `path` ("." for a bare file name): where its Gmsh mesh files are read from.
std::string job_directory(const std::string& path);

// One line per error: "<pointer>: <message>".
std::string format_errors(const std::vector<ValidationError>& errors);

}  // namespace contact::job
