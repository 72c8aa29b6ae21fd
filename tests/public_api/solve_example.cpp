// A program of the library's users: it includes only the public headers (solver/include/contact/) and links only
// contact_solver, whose private headers it cannot see. It reads an example job, solves it, writes the result file
// and reads it back, and checks what it can from physics: the job converges, every pair carries force, and the
// file holds the solve's steps. CTest: public_api.solve_example.
#include "contact/job.hpp"
#include "contact/progress_json.hpp"
#include "contact/result_file.hpp"
#include "contact/solve.hpp"

#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s job.json out.hdf\n", argv[0]);
    return 2;
  }
  const contact::job::ParseResult parsed = contact::job::parse_file(argv[1]);
  if (!parsed.ok()) {
    std::fprintf(stderr, "%s", contact::job::format_errors(parsed.errors).c_str());
    return 1;
  }
  struct Count final : contact::Observer {
    int reports = 0;
    void on_iteration(const contact::IterationReport& r) override {
      reports += contact::io::iteration_json(r, false).contains("pairs") ? 1 : 0;
    }
  } observer;
  contact::CancelToken cancel;
  const contact::Result result = contact::solve(*parsed.problem, observer, cancel);
  int failures = 0;
  auto check = [&](bool ok, const char* what) {
    if (!ok) {
      std::printf("FAIL %s\n", what);
      ++failures;
    }
  };
  check(result.converged, "the example converges");
  check(observer.reports == result.iterations, "one report per iteration");
  check(!result.steps.empty(), "a final step");
  for (const auto& pair : result.steps.back().pairs) check(pair.force > 0, "every pair carries force");
  contact::io::write_result(argv[2], *parsed.problem, result);
  const contact::io::ResultFile file = contact::io::read_result(argv[2]);
  check(file.steps.size() == result.steps.size(), "the file holds the solve's steps");
  std::printf("%d passed, %d failed\n", 4 + static_cast<int>(result.steps.back().pairs.size()) - failures, failures);
  return failures ? 1 : 0;
}
