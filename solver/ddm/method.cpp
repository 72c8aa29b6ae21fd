// The contact methods as classes behind ContactMethod (method.hpp), their facts, and the one place that picks them.
#include "method.hpp"

#include "interface/interface_newton.hpp"

namespace contact::ddm {

namespace {

// Without contact pairs the bodies are independent: one solve each is the answer, whatever the method.
void solve_independent_bodies(const ContactSystem& system, RunFrame& frame) {
  MethodOutcome& out = frame.outcome();
  std::vector<std::vector<char>> active;
  out.u = system.solve_bodies(Displacements(system.n_bodies()), frame.state().load);
  out.iterations = 1;
  out.subdomain_solves = 1;
  frame.report(system.report(1, out.u, frame.state(), active));
  out.converged = true;
  out.stop_reason = StopReason::converged;
  out.message = "no contact pairs: each body solved once";
}

class NeumannMethod final : public ContactMethod {
 public:
  using ContactMethod::ContactMethod;

 protected:
  void solve(RunFrame& frame) override { run_neumann(system_, frame); }
};

class RobinMethod final : public ContactMethod {
 public:
  using ContactMethod::ContactMethod;

 protected:
  void solve(RunFrame& frame) override { run_robin(system_, frame); }
};

class MonolithicMethod final : public ContactMethod {
 public:
  using ContactMethod::ContactMethod;
  void reset() override { memory_ = {}; }

 protected:
  void solve(RunFrame& frame) override { run_monolithic(system_, frame, memory_); }

 private:
  MonolithicMemory memory_;
};

// Keeps the interface problem between runs on the same meshes (augmented-Lagrangian updates and load steps only
// shift the gaps; the previous pressures warm-start the next solve).
class InterfaceNewtonMethod final : public ContactMethod {
 public:
  using ContactMethod::ContactMethod;
  void reset() override { interface_newton_.reset(); }

 protected:
  void solve(RunFrame& frame) override {
    int setup = 0;
    if (!interface_newton_) {
      interface_newton_ =
          std::make_unique<InterfaceNewton>(system_, frame.settings(), frame.runner(), frame.state().load);
      setup = 1;  // the free response of every body
    }
    interface_newton_->solve(frame);
    frame.outcome().subdomain_solves += setup;
  }

 private:
  std::unique_ptr<InterfaceNewton> interface_newton_;
};

}  // namespace

void ContactMethod::run(RunFrame& frame) {
  if (system_.pairs().empty()) return solve_independent_bodies(system_, frame);
  solve(frame);
}

const MethodFacts& facts_of(Method method) {
  using F = ContactSystem::Factorization;
  static const MethodFacts interface_newton{F::interface, "", false};
  static const MethodFacts fixed_point{F::plain, "", false};
  static const MethodFacts monolithic{
      F::none,
      "method 'monolithic' factorises all bodies as one system in one process: run it on one rank (without mpirun), "
      "or choose interface_newton, neumann or robin",
      true};
  switch (method) {
    case Method::interface_newton:
      return interface_newton;
    case Method::monolithic:
      return monolithic;
    case Method::neumann:
    case Method::robin:
      break;
  }
  return fixed_point;
}

std::unique_ptr<ContactMethod> make_method(const ContactSystem& system, Method method) {
  switch (method) {
    case Method::monolithic:
      return std::make_unique<MonolithicMethod>(system);
    case Method::robin:
      return std::make_unique<RobinMethod>(system);
    case Method::interface_newton:
      return std::make_unique<InterfaceNewtonMethod>(system);
    case Method::neumann:
      break;
  }
  return std::make_unique<NeumannMethod>(system);
}

}  // namespace contact::ddm
