// What a solve reports while it runs (IterationReport through an Observer) and what it returns (Result).
// The server plugs into Observer and CancelToken; the HDF5 writer consumes Result.
#pragma once

#include "contact/mesh.hpp"
#include "contact/warning.hpp"

#include <Eigen/Core>

#include <atomic>
#include <limits>
#include <string>
#include <vector>

namespace contact {

enum class StopReason { converged, max_iterations, stagnation, cancelled, error };
const char* to_string(StopReason r);

struct BodyReport {
  std::string name;
  int elements = 0;
  int dofs = 0;              // unknowns after constraints
  int elements_refined = 0;  // in this iteration (0 without adaptivity)
};

// Contact pressure is positive in compression; it is the nodal multiplier of the dual mortar discretisation
// (mortar/pair.hpp), one value per slave node (0 where a node carries none).
struct PairReport {
  std::string name;
  double force = 0.0;  // total normal contact force (per unit thickness in plane strain)
  Eigen::Vector2d resultant = Eigen::Vector2d::Zero();  // the force vector on the slave (PairField::resultant)
  double max_pressure = 0.0;
  double extent_begin = 0.0;      // arc lengths along the slave edge where the contact zone begins and ends,
  double extent_end = 0.0;        // interpolated between nodes (solver/contact_extent.hpp; both 0 without contact)
  int active_nodes = 0;           // slave nodes in contact (pressure > 0)
  int changed_nodes = 0;          // slave nodes whose contact status changed since the last iteration
  double theta = 0.0;             // penalty parameter (0 when contact is enforced exactly)
  double max_penetration = 0.0;   // largest overlap max(0, -g) of the nodal gaps
  std::vector<double> positions;  // arc length along the slave edge of each slave node
  std::vector<double> pressures;  // contact pressure at each slave node
  // Friction pairs only (empty otherwise): the tangential traction on the slave along its tangent at each slave
  // node, 1 where the node sticks, and the tangential force (sum of weight x tangential traction).
  std::vector<double> tangential_tractions;
  std::vector<int> stick;
  double tangential_force = 0.0;
  std::string friction;  // "coulomb" or "tresca" for friction pairs, empty otherwise
  double friction_coefficient = 0.0, friction_bound = 0.0;
};

// Which number decides convergence in a report: the fixed-point residual (Neumann, Robin, the paper's adaptive
// loop), the complementarity residual with the active-set changes (interface Newton, exact monolithic), or the
// energy gradient (penalty monolithic Newton, stored in fixed_point_residual).
enum class Measure { fixed_point, complementarity, gradient };
const char* to_string(Measure m);

struct IterationReport {
  int iteration = 0;  // 1-based
  Measure measure = Measure::fixed_point;
  double paper_criterion = 0.0;       // max over bodies of ||u_n^k - u_n^{k-1}|| / ||u_n^k|| (paper, section 4)
  double fixed_point_residual = 0.0;  // ||u~_n^{k+1} - u_n^k|| / ||u_n^k|| over all contact zones (fixed-point
                                      // methods); the relative energy gradient (monolithic penalty Newton)
  double complementarity = 0.0;       // active-set methods: ||z - max(0, z - c g)|| / ||z|| over all contact nodes
  int active_nodes = 0;               // contact nodes in contact, all pairs
  int active_set_changes = 0;         // contact nodes whose status changed since the last iteration, all pairs
  double gamma = 0.0;                 // relaxation in use (0 for methods without one)
  int update = 0;                     // augmented-Lagrangian update (0 for the pure penalty method)
  std::string note;                   // what changed in this iteration, if anything (e.g. "gamma reduced")
  // A collapse analysis: the multiplier of the trial this iteration belongs to (NaN outside the trials).
  double multiplier = std::numeric_limits<double>::quiet_NaN();
  std::vector<BodyReport> bodies;
  std::vector<PairReport> pairs;
  double elapsed_seconds = 0.0;
};

// The final fields of one body on its (final) mesh.
struct BodyField {
  std::string name;
  mesh::Mesh mesh;
  Eigen::MatrixX2d displacement;  // per node (x, y)
  Eigen::MatrixX4d stress_cell;   // per cell, mean over Gauss points: sxx, syy, sxy, szz
  Eigen::MatrixX4d stress_node;   // recovered per node (average of Gauss values extrapolated to the nodes)
  Eigen::VectorXd von_mises_cell;
  Eigen::VectorXd indicator_cell;  // error indicator per cell (empty without adaptivity)
  Eigen::MatrixX2d reaction;       // per node: force the supports exert (zero where nothing is prescribed)
  // Per displacement condition (edge or vertex, in the job's order): the sum of the reactions at its nodes in the
  // components it prescribes (a corner component prescribed by two conditions counts in both); and the sum over
  // all nodes, each once.
  struct SupportReaction {
    std::string where;  // the edge or vertex name
    Eigen::Vector2d force = Eigen::Vector2d::Zero();
  };
  std::vector<SupportReaction> support_reactions;
  Eigen::Vector2d reaction_total = Eigen::Vector2d::Zero();
  // A floating body (held by its contacts alone): its free rigid motions, and the rigid part of its displacement
  // as the translation (x, y) of rigid_center (the nodes' centroid) and a rotation (radians) about it.
  std::vector<std::string> free_motions;
  Eigen::Vector2d rigid_center = Eigen::Vector2d::Zero();
  Eigen::Vector3d rigid_motion = Eigen::Vector3d::Zero();
};

// A pair as a joint of a structure (a masonry bed joint, a voussoir's face): what an engineer reads of it, from its
// nodal pressures and tractions (joint_results). Over the nodes that carry a multiplier, each by its weight; the
// joint's extent is the arc length the pair carries (its nodes opposite the master, not another pair's). NaN where
// a value does not apply: a joint with no pressure has no centre of pressure, a frictionless one no slip fraction
// and no friction utilisation.
struct JointResults {
  double centre_of_pressure = 0.0;  // arc length along the slave edge of the pressure's resultant
  double eccentricity = 0.0;        // its offset from the joint's middle over the half-length, in [-1, 1]: |e| / (L/2)
  double open_fraction = 0.0;       // the share of the joint (by weight) with no pressure
  double slip_fraction = 0.0;       // the share in contact and slipping (friction)
  double friction_utilisation = 0.0;  // |T| / (mu N) (Coulomb), |T| / (g x the joint's weight) (Tresca)
};

// Contact quantities along one pair, at the slave edge's nodes, ordered along the slave edge. The gaps are the
// mortar (dual-weighted) nodal gaps, weighted gap / D; NaN where a slave node carries no multiplier (status).
struct PairField {
  std::string name;
  std::string slave_body, slave_edge, master_body, master_edge;
  std::string enforcement;      // "exact", "penalty" or "augmented_lagrangian"
  double theta = 0.0;           // penalty parameter (0 for exact enforcement)
  Eigen::VectorXi node;         // the slave nodes' indices in the slave body's mesh
  Eigen::MatrixX2d position;    // slave node coordinates
  Eigen::MatrixX2d normal;      // unit contact normal (outward of the slave); 0 where no multiplier
  Eigen::VectorXd arc_length;   // along the slave edge from its first node
  Eigen::VectorXd weight;       // D of the node's multiplier (length x thickness); 0 where none
  Eigen::VectorXd gap;          // initial nodal gap d (geometric + analytic)
  Eigen::VectorXd normal_gap;   // d - u_1n - u_2n after deformation (negative = penetration)
  Eigen::VectorXd pressure;     // the nodal multiplier z (exact) or max(0, lambda - normal_gap / theta)
  Eigen::VectorXd penetration;  // max(0, -normal_gap) (0 where no multiplier)
  Eigen::VectorXi active;       // 1 where the pressure is positive
  Eigen::VectorXi status;       // 0 contact node, 1 not opposite the master, 2 crosspoint, 3 barely covered,
                                // 4 inside a multiplier segment, 5 carried by another pair of its group
  double force = 0.0;           // sum of weight x pressure: the total normal force (a scalar sum of normal
                                // pressures: on a curved slave more than the load it carries)
  // The resultant contact force vector on the slave body (the master exerts it; the master receives its
  // opposite): the sum over the slave's nodes of its discrete contact forces -Gs^T z (with friction also the
  // tangential ones, -Ts^T q). Equal and opposite to the slave's other loads and reactions in equilibrium.
  Eigen::Vector2d resultant = Eigen::Vector2d::Zero();
  // Friction ("none", "coulomb" or "tresca"; the fields below are empty for "none"). The tangent is the normal
  // turned a quarter anticlockwise; the tangential traction is the master's traction on the slave along it; the
  // slip is the slave's tangential displacement relative to the master's (mortar-projected), accumulated over the
  // load steps; stick is 1 where a node in contact does not slip in this step (|t| below the bound), 0 where it
  // slips or is open.
  std::string friction = "none";
  double friction_coefficient = 0.0, friction_bound = 0.0;
  Eigen::MatrixX2d tangent;
  Eigen::VectorXd tangential_traction;
  Eigen::VectorXd slip;
  Eigen::VectorXi stick;
  double tangential_force = 0.0;  // sum of weight x tangential traction
  JointResults joint;             // the pair as a joint (joint_results)
};

// The joint results of a pair's fields (JointResults).
JointResults joint_results(const PairField& pair);

// One mesh state of the adaptive loop, or one load step; without either there is a single step.
struct Step {
  int index = 0;
  int iteration = 0;         // the DDM iteration at which this step's mesh was final
  double load_factor = 1.0;  // the load factor of this step (Problem::loading)
  double multiplier = 0.0;   // a collapse analysis's load multiplier of the live loads (0 without one)
  // Whether this step's solve converged. A step that did not is kept only as the last one of a run that stopped on
  // it (its iterate, flagged), never as an answer: the steps before it all converged.
  bool converged = true;
  std::vector<BodyField> bodies;
  std::vector<PairField> pairs;
};

// The scalars of one step (a row of /history/steps), kept for every step whatever Problem::output keeps of the
// steps' fields.
struct StepSummary {
  int index = 0;
  int iteration = 0;
  double load_factor = 1.0;
  double multiplier = 0.0;
  bool converged = true;
  std::vector<std::string> body_names;
  std::vector<int> elements, nodes;  // per body
  std::vector<std::string> pair_names;
  std::vector<double> force, contact_begin, contact_end;  // per pair: the total normal force, the contact zone
  std::vector<double> tangential_force;                   // per pair: friction's (0 for a frictionless pair)
};

// The step's scalars; the contact zone interpolated between nodes (solver/contact_extent.hpp; 0, 0 if none).
StepSummary summarize(const Step& step);

// The length of a pair's slave edge where it is a closed loop (its closing segment, from the last node back to
// the first, included), else 0.
double slave_loop_length(const Step& step, const PairField& pair);

// How a run ended and what it cost: what every level of a run builds (ddm::MethodOutcome adds the answer it carries
// between levels) and the Result reports, so the one is handed to the other whole.
struct RunOutcome {
  bool converged = false;
  StopReason stop_reason = StopReason::error;
  std::string message;  // human-readable detail of the stop (error text when stop_reason == error)
  int iterations = 0;
  double gamma = 0.0;              // relaxation used (0 for monolithic)
  int subdomain_solves = 0;        // back-substitutions per body (the DDM's unit of work), initial guess included
  int updates = 0;                 // augmented-Lagrangian updates (0 for the pure penalty method)
  std::string interface_solver;    // interface_newton: "direct" or "iterative" (solver.interface.solver)
  long interface_iterations = 0;   // the iterative interface solver's MPRGP iterations, all solves together
  double indicator_seconds = 0.0;  // adaptivity: estimating (for fem_bem: the boundary-element work)
  std::vector<IterationReport> history;
};

// A collapse mechanism (limit/mechanism.hpp): the rigid motion of each body that moves and what each joint (contact
// pair) does, at the scale where the largest body velocity is 1.
struct BodyMotion {
  std::string body;
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  // of the body's reference point (the mean of its nodes)
  double omega = 0.0;                                  // angular velocity, anticlockwise positive
  Eigen::Vector2d reference = Eigen::Vector2d::Zero();
  // Where the body turns about (its instantaneous centre), when it turns; NaN when it translates.
  Eigen::Vector2d centre = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::string words;  // "translates along (0.83, 0.55)", "turns clockwise about (2, 0)"
};
struct JointMotion {
  std::string pair;
  // "hinge" (the joint opens turning about a point of it), "slides" (along the joint), "opens" (separates without
  // turning on it), "opens and slides" (turns about a point off the joint)
  std::string kind;
  Eigen::Vector2d point = Eigen::Vector2d::Zero();  // a hinge's point; else the middle of the joint's rows
  double slip = 0.0;     // the slave's velocity along the pair's tangent relative to the master, at the point
  double opening = 0.0;  // the largest opening rate over the joint
  std::string words;
};
struct Mechanism {
  // "overturning", "sliding", "hinging" (several hinges), "mixed" (hinges and sliding), "lift-off" (joints that only
  // open), "unsupported" (bodies that move with no joint taking part), "" (none found)
  std::string kind;
  std::vector<BodyMotion> bodies;   // the bodies that move
  std::vector<JointMotion> joints;  // the joints that open or slide
  std::string words;                // one sentence: what moves and how
  // "elastic" (the rigid part of the elastic solution's last increment before the collapse, made exact and checked:
  // limit/elastic_mechanism.hpp) or "statics" (the rigid-block statics' dual at its bound: limit/statics.hpp)
  std::string source;
  std::string check;  // for an elastic one: its admissibility check in words (what passed, or what failed)
};

// A collapse analysis's answer (Problem::collapse; limit/collapse.hpp). The result's steps are the states that held
// along the way, each with its multiplier (the capacity curve); the last is the last that held.
struct CollapseResult {
  bool analysed = false;
  // "collapse" (bracketed: a multiplier held and a larger one did not), "holds" (no collapse up to
  // max_multiplier), "dead_loads_fail" (the loading's steps did not hold: the collapse multiplier was never
  // raised), "solver_failed" (the trials stopped before a bracket: max_solves, a cancel, an error)
  std::string verdict;
  double held = 0.0;                                         // the largest multiplier that held (lambda_c from below)
  double failed = std::numeric_limits<double>::quiet_NaN();  // the smallest that did not (lambda_c from above)
  bool failed_by_statics = false;  // `failed` exceeds the statics bound: refused without a solve
  // `failed` ran out of the iterative interface solver's budget (interface.max_iterations): the solver's limit, not a
  // proof of collapse; the verdict is then "solver_failed" and lambda_c >= held is all that is known.
  bool failed_by_budget = false;
  double tolerance = 0.0;
  int solves = 0;          // trial solves, each one load increment from the last state that held
  int bracket_solves = 0;  // of those, after the first failure (the bisection)
  // The rigid-block statics (limit/statics.hpp): the largest multiplier the bodies as rigid blocks carry with
  // associated friction, an upper bound of lambda_c; +inf when any multiple is carried, NaN when not computed.
  double statics_bound = std::numeric_limits<double>::quiet_NaN();
  // The collapse's mechanism: the elastic solution's own when it passes its check (source "elastic"), else the
  // statics' (source "statics", its `check` then says why the elastic one was not taken).
  Mechanism mechanism;
  Mechanism statics_mechanism;  // the statics' mechanism at its bound (associated friction), whatever `mechanism` is
  std::string words;            // the verdict as one paragraph (also the end of Result::message)
  // Every trial in order: its multiplier, whether it held, its solver iterations and its wall time (s), and at a
  // trial that held the live loads' displacement: the work of the live loads at multiplier 1 on the answer's
  // displacements over the sum of their nodal magnitudes, (f_live . u) / sum |f_live,i| (for one point load its
  // point's displacement along it; NaN where the trial did not hold). Against the multiplier: the capacity curve,
  // whose slope falls to zero at the collapse.
  struct Trial {
    double multiplier = 0.0;
    bool held = false;
    int iterations = 0;
    double seconds = 0.0;
    double displacement = std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<Trial> trials;
  // The live loads' displacement (Trial::displacement) at the loading's end, multiplier 0: the capacity curve's
  // first point (the dead loads move the live loads' points too). NaN when not computed.
  double start_displacement = std::numeric_limits<double>::quiet_NaN();
  // The thrust at the last state that held: each pair's centre of pressure on its slave edge (where its normal force
  // acts; NaN where the joint carries none), with the edge's two ends, the normal force and the eccentricity
  // (JointResults). Joined in the pairs' order where they form a chain (an arch, a column), the thrust line.
  struct Thrust {
    std::string pair, slave_body, master_body;
    Eigen::Vector2d point = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    Eigen::Vector2d first = Eigen::Vector2d::Zero(), last = Eigen::Vector2d::Zero();
    double force = 0.0;
    double eccentricity = std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<Thrust> thrust;
};

struct Result : RunOutcome {
  std::string method;       // "interface_newton", "neumann", "robin" or "monolithic"
  std::string enforcement;  // "exact", "penalty" or "augmented_lagrangian"
  // The steps whose fields are kept; the last one is the final solution; with StepOutput::last the only one. When
  // the observer stored the steps as they came (Observer::step_sink, streamed_steps > 0) only the last is here.
  std::vector<Step> steps;
  int streamed_steps = 0;  // how many steps the observer's StepSink took (0: none streamed, all are in `steps`)
  std::vector<StepSummary> step_history;  // every step's scalars, in order (solve() fills it; empty: from steps)
  // When the run did not converge: what the result keeps, as the end of `message` says it ("the result keeps the 2
  // load steps that held, not the last iterate (...)"); empty when it converged or nothing was solved.
  std::string kept;
  // The problem's warnings (before the solve) and the solve's (check/large_motion.hpp: displacements and rotations
  // that void the small-displacement model, floating bodies moved far), in that order.
  std::vector<Warning> warnings;
  CollapseResult collapse;  // a collapse analysis's answer (analysed false without one)
  double wall_seconds = 0.0;
  double setup_seconds = 0.0;  // assembly + factorisations
  double factorization_seconds = 0.0;
};

// A solve of the load path ended (not an iteration: each holds many): a load step or sub-step that held, a load
// step cut (its increment halved, from the load it reached), or a collapse analysis's trial (held or not). The
// progress says load steps, cuts and trials in these words, and solver iterations only in theirs.
struct LoadStepReport {
  enum class Kind { held, cut, trial };
  Kind kind = Kind::held;
  int step = 0;              // the load step, 1-based (a trial: the trial's number)
  int steps = 0;             // of how many load steps (0 for a trial)
  double fraction = 1.0;     // held/cut: the fraction of the step reached (1: the whole step)
  double next = 0.0;         // cut: the fraction the next sub-step tries
  double load_factor = 0.0;  // the loading's factor reached (held), or where the cut step stays (cut)
  double multiplier = std::numeric_limits<double>::quiet_NaN();  // a trial's multiplier
  bool held = true;                                              // a trial: whether it held
  int iterations = 0;                                            // the solver's iterations of this solve
  double elapsed_seconds = 0.0;
};

// One step of the adaptive loop (converge_then_refine), reported once its mesh is solved and estimated.
// Relative changes are against the previous step: |now - before| / max(|now|, |before|) (0 at step 0).
struct AdaptiveStepReport {
  int step = 0;                    // 0: the initial meshes
  std::vector<BodyReport> bodies;  // cells (elements), unknowns (dofs) and cells refined after this step, per body
  double estimate = 0.0;       // global: sqrt(sum ||sigma_R - sigma_F||^2 / sum ||sigma_R||^2) over the adaptive bodies
  double force = 0.0;          // total normal contact force, all pairs
  double peak_pressure = 0.0;  // largest contact pressure, all pairs
  // The changes the stop test reads (adapt/settled.hpp), against step `compared_with` (the last with at most half
  // the unknowns; -1 and NaN changes before there is one): the largest over the pairs of each pair's force and peak
  // pressure (relative to the largest pair's), of its contact zone's ends and stick zone's ends (relative to the
  // zone's width), of its tangential force; and the global estimate's (reported, not tested).
  int compared_with = -1;
  double force_change = 0.0, peak_change = 0.0, extent_change = 0.0, stick_change = 0.0, tangential_change = 0.0;
  double estimate_change = 0.0;
  // The estimated relative L2 error of the contact pressure over all pairs (adapt/pressure_estimate.hpp); NaN
  // where it cannot be made (the zz indicator, a cancel).
  double pressure_estimate = 0.0;
  double indicator_seconds = 0.0;  // this step's estimate (for fem_bem: the boundary-element work)
  double elapsed_seconds = 0.0;    // since solve() started
};

// Takes each step a run keeps, as soon as it is reached (a load step that held, an adaptive mesh state, and the
// iterate of a step that did not converge if OutputSettings::iterate asks for it), in order: io::ResultStream
// writes it to the result file, so that a run that keeps every step's fields does not hold them all in memory
// (1000 load steps of two 100 x 100 blocks held 2.3 GB until the end). Called from the thread that runs solve().
// An implementation that cannot store a step keeps the error for later (the solve goes on).
class StepSink {
 public:
  virtual ~StepSink() = default;
  virtual void take(const Step& step) = 0;
};

// Receives progress. Called from the thread that runs solve(), once per iteration, in order.
class Observer {
 public:
  virtual ~Observer() = default;
  virtual void on_iteration(const IterationReport&) {}
  virtual void on_adaptive_step(const AdaptiveStepReport&) {}
  virtual void on_load_step(const LoadStepReport&) {}
  // Where the steps go as they are reached when the job keeps every step's fields (StepOutput::all): solve() then
  // holds only the last one (Result::steps, Result::streamed_steps). nullptr: every kept step stays in memory.
  virtual StepSink* step_sink() { return nullptr; }
};

// Set from any thread; solve() checks it once per iteration and stops with StopReason::cancelled.
class CancelToken {
 public:
  void cancel() { cancelled_.store(true); }
  bool cancelled() const { return cancelled_.load(); }
  // For a token that serves another run after the one it stopped (contactd: a job moved out of its lane).
  void reset() { cancelled_.store(false); }

 private:
  std::atomic<bool> cancelled_{false};
};

}  // namespace contact
