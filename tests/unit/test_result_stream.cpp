// The result file written as the run goes (io::ResultStream, issue 32 item 1): each step's fields reach the file
// when the step is solved, the solver holds only the last one, and the file is the one write_result writes at the
// end from every step held in memory; an error or an abandoned run leaves no file under the final name.
#include "contact/job.hpp"
#include "contact/result_file.hpp"
#include "contact/solve.hpp"
#include "ddm/step_log.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

using namespace contact;
namespace fs = std::filesystem;

namespace {

fs::path output_dir(const std::string& leaf) {
  const fs::path dir = fs::path(CONTACT_BINARY_DIR) / "test_result_stream" / leaf;
  fs::create_directories(dir);
  return dir;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

Problem seed_in_steps() {
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/examples/seed_layers_steps.json");
  const auto parsed = job::parse(nlohmann::json::parse(in));
  EXPECT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  return *parsed.problem;
}

// Hands the steps to a sink and counts the iterations reported before each step arrived.
class Streaming final : public Observer {
 public:
  explicit Streaming(StepSink* sink) : sink_(sink) {}
  void on_iteration(const IterationReport&) override { ++iterations_; }
  StepSink* step_sink() override { return &counter_; }

  std::vector<int> iterations_at_step;

 private:
  struct Counter final : StepSink {
    Streaming* owner;
    explicit Counter(Streaming* o) : owner(o) {}
    void take(const Step& step) override {
      owner->iterations_at_step.push_back(owner->iterations_);
      owner->sink_->take(step);
    }
  } counter_{this};
  StepSink* sink_;
  int iterations_ = 0;
};

void expect_same_steps(const io::ResultFile& a, const io::ResultFile& b) {
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (size_t k = 0; k < a.steps.size(); ++k) {
    const Step& x = a.steps[k];
    const Step& y = b.steps[k];
    EXPECT_EQ(x.index, y.index) << k;
    EXPECT_EQ(x.load_factor, y.load_factor) << k;
    EXPECT_EQ(x.converged, y.converged) << k;
    ASSERT_EQ(x.bodies.size(), y.bodies.size());
    for (size_t i = 0; i < x.bodies.size(); ++i) {
      EXPECT_EQ(x.bodies[i].displacement, y.bodies[i].displacement) << k;
      EXPECT_EQ(x.bodies[i].stress_node, y.bodies[i].stress_node) << k;
      EXPECT_EQ(x.bodies[i].reaction, y.bodies[i].reaction) << k;
    }
    ASSERT_EQ(x.pairs.size(), y.pairs.size());
    for (size_t j = 0; j < x.pairs.size(); ++j) {
      EXPECT_EQ(x.pairs[j].pressure, y.pairs[j].pressure) << k;
      EXPECT_EQ(x.pairs[j].normal_gap, y.pairs[j].normal_gap) << k;
      EXPECT_EQ(x.pairs[j].force, y.pairs[j].force) << k;
    }
  }
}

}  // namespace

// The paper's problem in 10 load steps, solved twice: every step held in memory and written at the end, and
// every step streamed as it was solved. The solve is deterministic, so both files hold the same numbers bit for
// bit, the same histories and the same sidecar; the streamed run held one step, and each step reached the file
// before the run's last iteration.
TEST(ResultStream, StreamedFileIsTheFileWrittenAtTheEndWithOneStepInMemory) {
  const Problem problem = seed_in_steps();
  CancelToken never;
  Observer quiet;
  const Result held = solve(problem, quiet, never);
  ASSERT_TRUE(held.converged) << held.message;
  ASSERT_EQ(held.steps.size(), 10u);
  EXPECT_EQ(held.streamed_steps, 0);
  const fs::path at_end = output_dir("at_end") / "result.hdf";
  io::write_result(at_end.string(), problem, held);
  io::write_xdmf(io::xdmf_path_for(at_end.string()), "result.hdf", held);

  const fs::path streamed = output_dir("streamed") / "result.hdf";
  fs::remove(streamed);  // from an earlier run
  io::ResultStream stream(streamed.string(), io::xdmf_path_for(streamed.string()), "result.hdf");
  Streaming observer(&stream);
  const Result r = solve(problem, observer, never);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_EQ(r.steps.size(), 1u) << "only the last step stays in memory";
  EXPECT_EQ(r.streamed_steps, 10);
  EXPECT_EQ(stream.steps_taken(), 10u);
  EXPECT_FALSE(fs::exists(streamed)) << "nothing under the final name before finish";
  ASSERT_EQ(observer.iterations_at_step.size(), 10u);
  EXPECT_LT(observer.iterations_at_step.front(), r.iterations) << "the first step was stored as it was reached";
  stream.finish(problem, r);
  EXPECT_FALSE(fs::exists(streamed.string() + ".tmp"));

  const io::ResultFile a = io::read_result(at_end.string());
  const io::ResultFile b = io::read_result(streamed.string());
  expect_same_steps(a, b);
  EXPECT_EQ(a.step_history.force, b.step_history.force);
  EXPECT_EQ(a.step_history.load_factor, b.step_history.load_factor);
  EXPECT_EQ(a.history.iteration, b.history.iteration);
  EXPECT_EQ(a.converged, b.converged);
  EXPECT_EQ(a.stop_reason, b.stop_reason);
  EXPECT_EQ(a.vtkhdf.points, b.vtkhdf.points);
  EXPECT_EQ(read_text(io::xdmf_path_for(at_end.string())), read_text(io::xdmf_path_for(streamed.string())));
}

// With output.steps "last" a step is replaced by the next: nothing is streamed, the last step is written at the
// end as before.
TEST(ResultStream, LastStepOnlyIsNotStreamed) {
  Problem problem = seed_in_steps();
  problem.output.steps = StepOutput::last;
  const fs::path path = output_dir("last") / "result.hdf";
  io::ResultStream stream(path.string(), io::xdmf_path_for(path.string()), "result.hdf");
  Streaming observer(&stream);
  CancelToken never;
  const Result r = solve(problem, observer, never);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.streamed_steps, 0);
  EXPECT_TRUE(observer.iterations_at_step.empty());
  stream.finish(problem, r);
  const io::ResultFile f = io::read_result(path.string());
  ASSERT_EQ(f.steps.size(), 1u);
  EXPECT_EQ(f.steps[0].index, 9);
  EXPECT_EQ(f.step_history.load_factor.size(), 10u);
}

// A run that leaves no result (refused, nothing held) abandons the stream: the partial file is removed and the
// final name never appears; a stream destroyed unfinished does the same.
TEST(ResultStream, AbandonedOrDestroyedUnfinishedLeavesNoFile) {
  const Problem problem = seed_in_steps();
  const fs::path path = output_dir("abandoned") / "result.hdf";
  fs::remove(path);
  {
    io::ResultStream stream(path.string(), io::xdmf_path_for(path.string()), "result.hdf");
    Streaming observer(&stream);
    CancelToken never;
    const Result r = solve(problem, observer, never);
    ASSERT_EQ(r.streamed_steps, 10);
    EXPECT_TRUE(fs::exists(path.string() + ".tmp"));
    stream.abandon();
    EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
    EXPECT_THROW(stream.finish(problem, r), std::runtime_error);
  }
  {
    io::ResultStream stream(path.string(), io::xdmf_path_for(path.string()), "result.hdf");
    Streaming observer(&stream);
    CancelToken never;
    solve(problem, observer, never);
  }
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(io::xdmf_path_for(path.string())));
}

// A step that cannot be written (here: the directory is gone) does not stop the solve; finish() then throws the
// error naming the file, and nothing is left under either name.
TEST(ResultStream, AWriteErrorIsKeptForFinishWhichNamesTheFile) {
  const Problem problem = seed_in_steps();
  const fs::path dir = output_dir("gone");
  fs::remove_all(dir);
  const fs::path path = dir / "result.hdf";
  io::ResultStream stream(path.string(), io::xdmf_path_for(path.string()), "result.hdf");
  Streaming observer(&stream);
  CancelToken never;
  const Result r = solve(problem, observer, never);
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_EQ(stream.steps_taken(), 0u);
  try {
    stream.finish(problem, r);
    FAIL() << "finish did not throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
}

// The step log hands the sink every step it keeps and holds the last; a step that did not converge reaches it
// only when the iterate is asked for.
TEST(StepLog, WithASinkHoldsTheLastStepAndLeavesTheUnaskedIterateOut) {
  struct Names final : StepSink {
    std::vector<int> taken;
    void take(const Step& s) override { taken.push_back(s.index); }
  };
  for (const bool iterate : {false, true}) {
    Names sink;
    ddm::StepLog log(StepOutput::all, iterate, &sink);
    for (int k = 0; k < 4; ++k) {
      Step s;
      s.index = k;
      s.converged = k < 3;
      log.push_back(std::move(s));
    }
    EXPECT_EQ(sink.taken, iterate ? std::vector<int>({0, 1, 2, 3}) : std::vector<int>({0, 1, 2}));
    EXPECT_EQ(log.streamed(), iterate ? 4 : 3);
    EXPECT_EQ(log.held(), 3);
    EXPECT_EQ(log.dropped_iterate(), !iterate);
    const auto steps = log.take_steps();
    ASSERT_EQ(steps.size(), 1u);
    EXPECT_EQ(steps[0].index, iterate ? 3 : 2);
  }
}

// An iterate with non-finite values is never kept, asked for or not (issue 31, item 1).
TEST(StepLog, AnIterateWithNonFiniteValuesIsNeverKept) {
  ddm::StepLog log(StepOutput::all, /*keep_iterate=*/true);
  Step held;
  held.index = 0;
  log.push_back(held);
  Step bad;
  bad.index = 1;
  bad.converged = false;
  PairField p;
  p.arc_length = Eigen::VectorXd::LinSpaced(3, 0.0, 1.0);
  p.status = Eigen::VectorXi::Zero(3);
  p.pressure = Eigen::VectorXd::Constant(3, 1.0);
  p.pressure[1] = std::numeric_limits<double>::infinity();
  p.normal_gap = Eigen::VectorXd::Zero(3);
  bad.pairs.push_back(p);
  log.push_back(bad);
  EXPECT_TRUE(log.dropped_iterate());
  EXPECT_TRUE(log.dropped_unfit());
  const auto steps = log.take_steps();
  ASSERT_EQ(steps.size(), 1u);
  EXPECT_EQ(steps[0].index, 0);
  // A finite one is kept when asked for; NaN where a node has no value (status other than 0) is no reason to
  // drop it (docs/results-format.md), NaN at a contact node is.
  ddm::StepLog asked(StepOutput::all, true);
  bad.pairs[0].pressure[1] = 2.0;
  bad.pairs[0].status[2] = 2;
  bad.pairs[0].normal_gap[2] = std::numeric_limits<double>::quiet_NaN();
  asked.push_back(bad);
  EXPECT_FALSE(asked.dropped_iterate());
  EXPECT_EQ(asked.take_steps().size(), 1u);
  ddm::StepLog nan_at_contact(StepOutput::all, true);
  bad.pairs[0].normal_gap[0] = std::numeric_limits<double>::quiet_NaN();
  nan_at_contact.push_back(bad);
  EXPECT_TRUE(nan_at_contact.dropped_unfit());
}
