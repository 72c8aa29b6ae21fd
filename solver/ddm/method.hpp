// The one interface every contact method (interface Newton, Neumann DDM, Robin, monolithic reference) shares
// (ContactMethod, made by make_method) and the facts each declares about itself (MethodFacts, facts_of), so that
// the outer loops (augmented Lagrangian, load steps, adaptivity) and solve() know no method by name: method.cpp
// is the one place that does.
#pragma once

#include "../linalg/friction_sets.hpp"
#include "run_frame.hpp"

#include <memory>
#include <string>

namespace contact::ddm {

// A contact method on a ContactSystem: run() solves once on the pairs' current gaps (and augmented-Lagrangian
// multipliers) under the frame's settings, building the frame's outcome; without contact pairs every method's
// answer is each body solved once, which run() gives for all. A method may keep what it built for the system
// between runs (interface Newton: its interface problem); reset() forgets it after the meshes changed. A new
// method is a class in method.cpp, a case in make_method and its facts in facts_of.
class ContactMethod {
 public:
  explicit ContactMethod(const ContactSystem& system) : system_(system) {}
  virtual ~ContactMethod() = default;
  ContactMethod(const ContactMethod&) = delete;
  ContactMethod& operator=(const ContactMethod&) = delete;

  void run(RunFrame& frame);
  virtual void reset() {}

 protected:
  virtual void solve(RunFrame& frame) = 0;
  const ContactSystem& system_;
};

// What solve() must know of a method before and after it runs, declared by the method.
struct MethodFacts {
  // The bodies' factorisations it needs (the monolithic reference factorises the coupled system itself; interface
  // Newton needs each body's contact unknowns last, for the Schur complements).
  ContactSystem::Factorization factorization = ContactSystem::Factorization::plain;
  // Why it cannot run with its bodies spread over processes (empty: it can).
  std::string not_distributed;
  // Whether its solution must be checked once the run ends (the monolithic reference: held floating bodies,
  // held_bodies.hpp); such a run keeps its steps until then (they are not streamed to the result file).
  bool checks_held_bodies = false;
};

const MethodFacts& facts_of(Method method);

std::unique_ptr<ContactMethod> make_method(const ContactSystem& system, Method method);

// The paper's parallel Neumann scheme (16)-(17) on fixed meshes.
void run_neumann(const ContactSystem& system, RunFrame& frame);

// The Robin-type variant (docs/algorithm.md): each body's matrix carries the Robin weight on its contact zone.
void run_robin(const ContactSystem& system, RunFrame& frame);

// What the monolithic reference keeps between runs on the same meshes: the contact and stick/slip sets of its last
// converged answer, the next load step's (sub-step's, collapse trial's) first sets.
struct MonolithicMemory {
  linalg::FrictionSets sets;
  Eigen::VectorXd x, lambda;  // its stacked unknowns and multipliers: the augmented Lagrangian's start
};

// The same discrete problem (exact or penalty, per the settings' enforcement) solved in one system: the
// reference solver (monolithic.cpp).
void run_monolithic(const ContactSystem& system, RunFrame& frame, MonolithicMemory& memory);

}  // namespace contact::ddm
