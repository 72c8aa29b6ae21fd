// The contact methods as classes behind ContactMethod (method.hpp), and the one place that picks them.
#include "method.hpp"

#include "interface/interface_newton.hpp"

namespace contact::ddm {

namespace {

// Without contact pairs the bodies are independent: one solve each is the answer, whatever the method.
MethodOutcome solve_independent_bodies(const ContactSystem& system, RunContext& context) {
  MethodOutcome out;
  std::vector<std::vector<char>> active;
  out.u = system.solve_bodies(Displacements(system.n_bodies()), context.runner);
  out.iterations = 1;
  out.solves_per_body = 1;
  IterationReport r = system.report(1, out.u, active);
  r.elapsed_seconds = context.elapsed();
  context.observer.on_iteration(r);
  out.history.push_back(std::move(r));
  out.converged = true;
  out.reason = StopReason::converged;
  out.message = "no contact pairs: each body solved once";
  return out;
}

class NeumannMethod final : public ContactMethod {
 public:
  using ContactMethod::ContactMethod;

 protected:
  MethodOutcome solve(RunContext& context) override { return run_neumann(system_, settings_, context); }
};

class RobinMethod final : public ContactMethod {
 public:
  using ContactMethod::ContactMethod;

 protected:
  MethodOutcome solve(RunContext& context) override { return run_robin(system_, settings_, context); }
};

class MonolithicMethod final : public ContactMethod {
 public:
  using ContactMethod::ContactMethod;

 protected:
  MethodOutcome solve(RunContext& context) override { return run_monolithic(system_, settings_, context); }
};

// Keeps the interface problem between runs on the same meshes (augmented-Lagrangian updates and load steps only
// shift the gaps; the previous pressures warm-start the next solve).
class InterfaceNewtonMethod final : public ContactMethod {
 public:
  using ContactMethod::ContactMethod;
  void reset() override { interface_newton_.reset(); }

 protected:
  MethodOutcome solve(RunContext& context) override {
    int setup = 0;
    if (!interface_newton_) {
      interface_newton_ = std::make_unique<InterfaceNewton>(system_, settings_, context.runner);
      setup = 1;  // the free response of every body
    }
    MethodOutcome out = interface_newton_->solve(settings_, context);
    out.solves_per_body += setup;
    return out;
  }

 private:
  std::unique_ptr<InterfaceNewton> interface_newton_;
};

}  // namespace

MethodOutcome ContactMethod::run(RunContext& context) {
  if (system_.pairs().empty()) return solve_independent_bodies(system_, context);
  return solve(context);
}

std::unique_ptr<ContactMethod> make_method(const ContactSystem& system, const SolverSettings& settings) {
  switch (settings.method) {
    case Method::monolithic: return std::make_unique<MonolithicMethod>(system, settings);
    case Method::robin: return std::make_unique<RobinMethod>(system, settings);
    case Method::interface_newton: return std::make_unique<InterfaceNewtonMethod>(system, settings);
    case Method::neumann: break;
  }
  return std::make_unique<NeumannMethod>(system, settings);
}

}  // namespace contact::ddm
