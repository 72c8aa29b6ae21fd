// A contact problem as plain data: what job::parse produces from a job JSON and what solve() consumes.
//
// Units are the user's (the examples use cm and MPa). Sign conventions, stated once here:
//  * displacements and tractions are vectors in the global x-y frame;
//  * a traction {"normal": p} is a pressure: p > 0 pushes into the body (t = -p n, n the outward normal);
//  * contact pressure is reported positive in compression (the paper's sigma_n = -pressure <= 0).
#pragma once

#include "contact/mesh.hpp"
#include "contact/warning.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace contact {

enum class Plane { strain, stress };

struct Model {
  Plane plane = Plane::strain;
  double thickness = 1.0;  // out-of-plane thickness; forces are per this thickness (plane stress only)
  // The acceleration of gravity (a vector: [0, -9.81] in m/s^2); every body weighs density x gravity per volume, a
  // body force that follows the loading's factor (docs/job-format.md, "Loads").
  Eigen::Vector2d gravity = Eigen::Vector2d::Zero();
};

struct Material {
  double E = 0.0;        // Young's modulus, > 0
  double nu = 0.0;       // Poisson's ratio, in (-1, 0.5)
  double density = 0.0;  // mass per volume, >= 0: the body's weight under Model::gravity
};

// One boundary condition on a named edge, or at a named vertex, of a body. Edges without a condition are
// traction-free. Loads and prescribed displacements are scaled by the load factor of the step being solved.
// `kind` is the load (traction, force) or its absence (displacement only, free); prescribed displacement components
// (ux, uy) may come with a load on the other component (a sliding support that is pushed, a point held in x and
// loaded in y).
struct BoundaryCondition {
  enum class Kind { displacement, traction, force, free };
  std::string edge;
  Kind kind = Kind::free;
  std::string vertex;  // instead of an edge: a named vertex (Mesh::vertices): a point support or a point load
  // displacement: only the given components are prescribed
  std::optional<double> ux, uy;
  // traction: either a vector (force per length) or a normal pressure (positive = pushing into the body)
  bool normal_pressure = false;
  Eigen::Vector2d traction = Eigen::Vector2d::Zero();
  double pressure = 0.0;
  // force: the total force on the edge, spread as a uniform traction, or a point load at the vertex (per unit
  // thickness in plane strain, the total in plane stress, like every force)
  Eigen::Vector2d force = Eigen::Vector2d::Zero();
  // This condition's own load factor for each load step (its value is scaled by history[k] in step k instead of
  // the loading's factor): a normal load held while a tangential one grows. Empty: it follows the loading.
  std::vector<double> history;
  // A live load of a collapse analysis (Problem::collapse): scaled by the load multiplier lambda instead of the
  // loading's factor (0 during the loading's steps, which bring the dead loads on). Loads only, never a history.
  bool live = false;
};

inline bool prescribes_displacement(const BoundaryCondition& bc) { return bc.ux.has_value() || bc.uy.has_value(); }

// The nodes a condition acts on: the vertex's node, or the edge's nodes in order (empty if unknown).
inline std::vector<int> condition_nodes(const mesh::Mesh& mesh, const BoundaryCondition& bc) {
  if (!bc.vertex.empty()) {
    auto it = mesh.vertices.find(bc.vertex);
    return it == mesh.vertices.end() ? std::vector<int>{} : std::vector<int>{it->second};
  }
  return mesh.edge_set_nodes(bc.edge);
}

struct Body {
  std::string name;
  Material material;
  mesh::Mesh mesh;
  std::vector<BoundaryCondition> boundary;
  Eigen::Vector2d body_force = Eigen::Vector2d::Zero();  // force per volume (optional; zero in the paper)
  // body_force's own load factor per load step, as a condition's history (empty: it follows the loading): a
  // horizontal seismic coefficient ramped while the weight (density x gravity) is held.
  std::vector<double> body_force_history;
  bool body_force_live = false;  // body_force is a live load of the collapse analysis (as BoundaryCondition::live)

  // The body's weight per volume under `gravity`, a body force besides body_force.
  Eigen::Vector2d weight(const Eigen::Vector2d& gravity) const { return material.density * gravity; }
};

// The initial gap d(x) at a slave point x: the geometric normal distance to the master edge (unless switched
// off) plus optional analytic terms, e.g. the paper's d = r0 (x - x0)^2.
struct GapSpec {
  bool geometric = true;
  double constant = 0.0;              // added everywhere
  std::optional<double> parabola_r0;  // adds r0 (x - x0)^2, x the slave point's x coordinate
  double parabola_x0 = 0.0;
};

// Friction of a contact pair (docs/algorithm.md, "Friction"): none (frictionless), Coulomb (|t| <= mu p at every
// contact node) or Tresca (|t| <= bound, a given traction: force per unit length and thickness, like p).
struct FrictionSpec {
  enum class Law { none, coulomb, tresca };
  Law law = Law::none;
  double coefficient = 0.0;  // Coulomb's mu
  double bound = 0.0;        // Tresca's g
  bool active() const { return law != Law::none; }
};

// What the drawing of a pair's edges means (docs/job-format.md, "fit"): touching (the edges drawn on each other:
// an overlap or a pair open everywhere is a modelling mistake, warned of), interference (drawn overlapping: a shrink
// or press fit) or clearance (drawn apart: a pin in a larger hole, a punch above its block).
enum class Fit { touching, interference, clearance };

struct ContactPair {
  std::string name;     // "slave_body.edge-master_body.edge" unless the job names it
  int slave_body = -1;  // index into Problem::bodies
  std::string slave_edge;
  int master_body = -1;
  std::string master_edge;
  GapSpec gap;
  FrictionSpec friction;
  Fit fit = Fit::touching;
};

// theta = c * length / E_pair unless theta is given. E_pair is the harmonic mean 2 E1 E2 / (E1 + E2) of the
// pair's Young's moduli (E itself for equal bodies); length defaults to the smaller of the two bodies' extents
// along the contact normal (the body height in the paper), the master edge's mean normal; a closed master edge
// (a shaft's rim, a bore) has none, and a body's extent is then the smaller of its extents along x and y.
struct PenaltySpec {
  std::optional<double> theta;
  double c = 0.05;
  std::optional<double> length;
};

// interface_newton: each body's Schur complement on its contact unknowns (from its factorisation), the primal-dual
// active set (semismooth Newton) on the nodal pressures, one final solve per body; neumann: the paper's scheme
// (16)-(17); robin: the Robin-type variant; monolithic: all bodies in one system (the reference). See
// docs/algorithm.md for when to use which.
enum class Method { neumann, monolithic, interface_newton, robin };
enum class Criterion { paper, residual };
enum class InitialGuess { zero, elastic_layer };
enum class Acceleration { none, anderson };
// exact: z >= 0, g >= 0, z g = 0 at every contact node (dual mortar multipliers); penalty: the paper's
// z = max(0, -g / theta) in nodal form; augmented_lagrangian: Uzawa updates of the penalty problem, exact in the
// limit (for the penalty-based fixed-point schemes neumann and robin).
enum class Enforcement { exact, penalty, augmented_lagrangian };

// The job format's names of the methods and enforcements, one table each (problem.cpp): the job reader takes them,
// the result and the progress report give them back.
const char* to_string(Method m);
const char* to_string(Enforcement e);
std::optional<Method> method_named(const std::string& name);
std::optional<Enforcement> enforcement_named(const std::string& name);
// Every name of the table, in its order: what the job reader accepts and lists in its messages.
std::vector<std::string> method_names();
std::vector<std::string> enforcement_names();

// Robin weight psi (force per length^3, like 1/theta): a constant over every contact zone, or 1/theta on the
// current active set and 0 elsewhere ("active_set").
struct RobinSettings {
  bool active_set = true;
  double psi = 0.0;
};

// Uzawa updates of the contact pressure around the penalty solve: stop when the relative change of the
// pressures between two updates is below tolerance.
struct AugmentedLagrangianSettings {
  double tolerance =
      1e-6;  // at least ~100 times the inner solve's tolerance: the inner solves bound the attainable change
  int max_updates = 100;
};

// How interface_newton solves its interface problem (docs/algorithm.md, "The interface solvers"): direct, the
// active set on the sparse assembled interface matrix (CHOLMOD), one process; iterative, FETI-style projected
// MPRGP with SMALBE for the floating bodies' equilibrium, each process applying its own bodies' blocks; automatic
// picks by size. Both give the same discrete solution.
enum class InterfaceSolverKind { automatic, direct, iterative };
// automatic: none on many floating bodies (the iterative solver's many-body case), dirichlet otherwise
// (interface_solver.cpp, resolved_settings).
enum class InterfacePreconditioner { none, lumped, dirichlet, automatic };
struct InterfaceSolverSettings {
  InterfaceSolverKind solver = InterfaceSolverKind::automatic;
  InterfacePreconditioner preconditioner = InterfacePreconditioner::automatic;  // iterative only
  double tolerance = 1e-12;      // iterative: projected gradient and equilibrium, relative
  long max_iterations = 300000;  // iterative: products with the interface operator, in all
};

// Defaults: exact contact by interface Newton. The job parser fills the defaults that depend on the method
// (enforcement: exact for interface_newton and monolithic, penalty for neumann and robin); the paper's scheme is
// method neumann, gamma 0.02, criterion paper, tolerance 0.0015, acceleration none
// (api/examples/seed_layers.json spells it out).
struct SolverSettings {
  Method method = Method::interface_newton;
  PenaltySpec penalty;
  double gamma = 0.02;      // relaxation of (17) when gamma_auto is false
  bool gamma_auto = true;   // estimate the interface compliance and choose gamma (overrides gamma)
  double tolerance = 1e-8;  // eps of the chosen criterion (fixed-point methods)
  Criterion criterion = Criterion::residual;
  int max_iterations = 2000;  // iterations (fixed-point methods) or active-set / Newton steps
  InitialGuess initial_guess = InitialGuess::elastic_layer;
  int threads = 0;  // worker threads for the per-body solves; 0 = one per body up to the cores
  Acceleration acceleration = Acceleration::anderson;
  int anderson_depth = 10;
  RobinSettings robin;
  Enforcement enforcement = Enforcement::exact;
  AugmentedLagrangianSettings augmented_lagrangian;
  InterfaceSolverSettings interface;
};

// neumann and robin iterate on the penalty problem (exact contact only in the limit, through augmented_lagrangian):
// penalty is their default enforcement, exact is not available to them.
bool iterates_on_penalty(Method method);

// Why these settings cannot run together, in the one wording both the job reader (at the job's pointer) and
// solve() (for a Problem built in code) give; empty when they can. The rule: exact enforcement with a method that
// iterates on the penalty problem.
std::string settings_conflict(const SolverSettings& settings);

// Why these settings cannot solve a frictional contact, in the one wording of the job reader (at the friction's
// pointer) and of the solvers (for a Problem built in code); empty when they can. Friction is solved on the
// interface problem or the monolithic one (not by neumann or robin), with exact contact.
std::string friction_conflict(const SolverSettings& settings);

// h-adaptivity (paper section 3): indicator per cell, refine where it exceeds delta.
enum class Indicator { fem_bem, zz };
// paper: one DDM update, then estimate and refine, every iteration (the paper's interleaving);
// converge_then_refine: solve on the mesh, then estimate and refine; repeat.
enum class AdaptStrategy { paper, converge_then_refine };
// How eta is normalised (docs/algorithm.md, "Indicators"): rms = (||.||_e / sqrt|e|) / (||.||_Omega / sqrt|Omega|),
// root-mean-square error over the cell against root-mean-square stress over the body; area = the formula as
// printed in the paper, (||.||_e / |e|) / (||.||_Omega / |Omega|), which grows like 1/sqrt|e| under refinement
// and so never stops refining where the relative error is only O(h).
enum class Normalization { rms, area };
// Which cells over delta are refined (docs/algorithm.md, "Marking that serves the contact"): plain = all of them
// (the paper); contact = the cells along the contact zones held to a tighter delta, and with grading > 0 none
// already smaller than grading x their distance to the nearest zone; goal = not by delta: Doerfler's marking of the
// cells holding half the pressure estimate's correction (adapt/goal_marking.hpp, as with a target_error), where
// that estimate can be made (else as contact). The job reader's default is goal for the fem_bem indicator with
// converge_then_refine and a domain-decomposition method when the job gives no delta, contact otherwise; a
// Problem built in code has contact.
enum class MarkingRule { contact, plain, goal };

struct AdaptivitySettings {
  bool enabled = false;
  Indicator indicator = Indicator::fem_bem;
  Normalization normalization = Normalization::rms;
  double delta = 0.1;
  MarkingRule marking = MarkingRule::contact;
  double grading = 0.0;  // marking contact: cells below grading x distance to the contact zone are not refined (0: off)
  std::vector<int> bodies;  // indices of the adaptive bodies; empty = all
  int max_level = 8;        // refinement levels above the initial mesh
  long max_dofs = 400000;   // per body; refinement that would exceed it is cut back (and reported)
  // Over all bodies: the job reader sets it to the limit on unknowns the job was admitted under (job::Limits,
  // --max-dofs of contact-solve and contactd), so refinement never takes a job past what it could be submitted
  // with (0: no total limit, a Problem built in code).
  long max_total_dofs = 0;
  // The limit on the interface problem's memory the job was admitted under (job::Limits::max_interface_bytes, for
  // method interface_newton; 0: none): a refinement whose meshes would take the interface past it is not made
  // (estimate_interface_memory), and the run stops refining there.
  double max_interface_bytes = 0;
  // The result's budget in mesh nodes summed over the steps it keeps (the job reader sets it from the limit on
  // the result's size, job::Limits::max_result_bytes; 0: none): a mesh that would take the kept steps past it is
  // not made (refinement is cut back, as by max_total_dofs).
  double max_kept_nodes = 0;
  AdaptStrategy strategy = AdaptStrategy::converge_then_refine;
  int max_steps = 20;  // refinement steps (converge_then_refine)
  // converge_then_refine stops once the answer has settled to this (adapt/settled.hpp): each pair's force, peak
  // pressure, contact zone's ends and, with friction, stick zone's ends and tangential force changed by less than
  // this, relatively, against the last step with at most half the unknowns, at two steps in a row (0: never stop for
  // that reason).
  double stop_tolerance = 0.005;
  // converge_then_refine stops at the first step whose estimated relative error of the contact pressure
  // (adapt/pressure_estimate.hpp) is at most this; where nothing is marked before, delta is halved (0: no target).
  double target_error = 0.0;
};

// Load steps: every prescribed displacement, traction, force and body force is scaled by each factor in turn;
// each step is solved starting from the previous one and stored as a result step. {1} = one step, the full load.
struct LoadingSpec {
  std::vector<double> factors = {1.0};
};

// A collapse analysis (the job's "collapse", docs/limit-analysis.md): once the loading's steps have brought the dead
// loads on, the live loads (BoundaryCondition::live, Body::body_force_live) are raised by a load multiplier lambda
// from 0, by increments the analysis adapts, until a trial does not hold; the limit is then bracketed by bisection,
// each trial from the last state that held, to `tolerance` relative (limit/collapse.hpp).
struct CollapseSpec {
  bool enabled = false;
  double tolerance = 1e-3;      // the bracket's width relative to the multiplier that held
  double first = 0.0;           // the first trial multiplier (0: half the rigid-block statics bound, else 1)
  double max_multiplier = 1e6;  // no collapse up to this: the answer is "holds up to max_multiplier"
  int max_solves = 60;          // trial solves at most (each one load increment)
};

// Which steps the result keeps whole (the job's "output"): every step's fields, or the last step's only. The
// scalars of every step (Result::step_history, /history/steps) are kept either way. The job reader's default is
// `last` for adaptive jobs and `all` otherwise (docs/job-format.md, "Output"); a Problem built in code keeps all.
enum class StepOutput { all, last };
struct OutputSettings {
  StepOutput steps = StepOutput::all;
  // The pairs whose detail the progress lists (shell globs on pair names; contact/progress_json.hpp). Empty: every
  // pair while they are few, past that a summary and the pairs that stand out.
  std::vector<std::string> progress_pairs;
  // Whether a step whose solve did not converge (a load step that could not be held, a run stopped by
  // max_iterations, stagnation or a cancel) keeps its last iterate in the result, flagged converged 0. Not by
  // default: the result then holds the steps that held only, and a run in which none held writes none.
  bool iterate = false;
};

struct Problem {
  std::string name;
  Model model;
  std::vector<Body> bodies;
  std::vector<ContactPair> contacts;
  SolverSettings solver;
  AdaptivitySettings adaptivity;
  LoadingSpec loading;
  CollapseSpec collapse;
  OutputSettings output;
  int ranks = 1;        // parallel.ranks: MPI ranks a server launches (contact-solve takes mpirun's)
  bool strict = false;  // warnings are errors (the job's "strict", contact-solve --strict)
  // What the model checks found before the solve (check/initial_gaps.hpp: overlaps and open pairs), as the job
  // reader reports them; the solve adds its own to Result::warnings.
  std::vector<Warning> warnings;
  nlohmann::json submitted;   // the job JSON as submitted
  nlohmann::json normalized;  // the same with every default filled in

  bool has_friction() const {
    for (const auto& c : contacts)
      if (c.friction.active()) return true;
    return false;
  }
};

// The memory of the interface problem that method interface_newton builds (ddm/interface/interface_problem.hpp),
// from the contact edges' node counts alone, before anything is factorised. Body a holds dense blocks over its
// contact unknowns (z_a: two per node of its contact edges) and its pairs' rows (r_a: a pair's slave nodes, twice
// with friction): the trailing block of its factor (z_a x z_a), W_a = L^-1 B^T (z_a x r_a), F_a (r_a x r_a), and a
// few r_a x r_a more for the preconditioner, the direct solver's assembled copy and factor (3 in all frictionless,
// 6 with friction: its Newton matrices). Measured on two strips of N cells in contact (N = 1,000 and 2,000):
// 125 N^2 bytes, 500 N^2 with friction; this estimate gives 144 N^2 and 512 N^2. The job reader refuses a job
// over --max-interface-bytes with it; an adaptive run stops refining where its next meshes would be
// (AdaptivitySettings::max_interface_bytes).
struct InterfaceMemoryEstimate {
  double bytes = 0.0;          // all bodies together
  double largest = 0.0;        // the body that takes the most...
  size_t body = 0;             // ...its index
  double contact_nodes = 0.0;  // ...and its contact nodes
};
// `edge_nodes(body, edge)`: the nodes of that body's edge (or edge set), each pair's edges counted once a body.
InterfaceMemoryEstimate estimate_interface_memory(const std::vector<ContactPair>& contacts, size_t bodies,
                                                  const std::function<double(int, const std::string&)>& edge_nodes);

}  // namespace contact
