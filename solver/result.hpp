// What a solve reports while it runs (IterationReport through an Observer) and what it returns (Result).
// The server plugs into Observer and CancelToken; the HDF5 writer consumes Result.
#pragma once

#include "mesh/mesh.hpp"

#include <Eigen/Core>

#include <atomic>
#include <string>
#include <vector>

namespace contact {

enum class StopReason { converged, max_iterations, stagnation, cancelled, error };
const char* to_string(StopReason r);

struct BodyReport {
  std::string name;
  int elements = 0;
  int dofs = 0;             // unknowns after constraints
  int elements_refined = 0; // in this iteration (0 without adaptivity)
};

// Contact pressure is positive in compression. Positions are the slave evaluation points (see PairField).
struct PairReport {
  std::string name;
  double force = 0.0;          // total normal contact force (per unit thickness in plane strain)
  double max_pressure = 0.0;
  double extent_begin = 0.0;   // arc length along the slave edge of the first and last active point
  double extent_end = 0.0;     // (both 0 when nothing is in contact)
  int active_points = 0;       // quadrature points in contact
  int changed_points = 0;      // quadrature points whose contact status changed since the last iteration
  double theta = 0.0;          // penalty parameter in use
  double max_penetration = 0.0;   // largest overlap max(0, -g) at the slave nodes
  std::vector<double> positions;  // arc length along the slave edge of each slave node
  std::vector<double> pressures;  // contact pressure at each slave node
};

struct IterationReport {
  int iteration = 0;                // 1-based
  double paper_criterion = 0.0;     // max over bodies of ||u_n^k - u_n^{k-1}|| / ||u_n^k|| (paper, section 4)
  double fixed_point_residual = 0.0;// ||u~_n^{k+1} - u_n^k|| / ||u_n^k|| over all contact zones
  double gamma = 0.0;               // relaxation in use (0 for methods without one)
  int update = 0;                   // augmented-Lagrangian update (0 for the pure penalty method)
  std::string note;                 // what changed in this iteration, if anything (e.g. "gamma reduced")
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
  Eigen::VectorXd indicator_cell; // error indicator per cell (empty without adaptivity)
  Eigen::MatrixX2d reaction;      // per node: force the supports exert (zero where nothing is prescribed)
};

// Contact quantities along one pair, at the slave edge's nodes, ordered along the slave edge.
struct PairField {
  std::string name;
  std::string slave_body, slave_edge, master_body, master_edge;
  double theta = 0.0;
  Eigen::MatrixX2d position;     // slave node coordinates
  Eigen::VectorXd arc_length;    // along the slave edge from its first node
  Eigen::VectorXd gap;           // initial gap d (geometric + analytic)
  Eigen::VectorXd normal_gap;    // d - u_1n - u_2n after deformation (negative = penetration)
  Eigen::VectorXd pressure;      // max(0, lambda - normal_gap / theta) (lambda = 0 without augmented Lagrangian)
  Eigen::VectorXd penetration;   // max(0, -normal_gap)
  Eigen::VectorXi active;        // 1 where the pressure is positive
  double force = 0.0;            // integral of the pressure over the slave edge (quadrature of the solver)
};

// One mesh state: without adaptivity there is a single step.
struct Step {
  int index = 0;
  int iteration = 0;  // the DDM iteration at which this step's mesh was final
  std::vector<BodyField> bodies;
  std::vector<PairField> pairs;
};

struct Result {
  bool converged = false;
  StopReason stop_reason = StopReason::error;
  std::string message;  // human-readable detail of the stop (error text when stop_reason == error)
  int iterations = 0;
  std::string method;   // "neumann" or "monolithic"
  double gamma = 0.0;   // relaxation used (0 for monolithic)
  int subdomain_solves = 0;  // back-substitutions per body (the DDM's unit of work), initial guess included
  int updates = 0;           // augmented-Lagrangian updates (0 for the pure penalty method)
  std::vector<IterationReport> history;
  std::vector<Step> steps;  // the last one is the final solution
  double wall_seconds = 0.0;
  double setup_seconds = 0.0;       // assembly + factorisations
  double factorization_seconds = 0.0;
  double indicator_seconds = 0.0;   // adaptivity: estimating (for fem_bem: the boundary-element work)
};

// Receives progress. Called from the thread that runs solve(), once per iteration, in order.
class Observer {
 public:
  virtual ~Observer() = default;
  virtual void on_iteration(const IterationReport&) {}
};

// Set from any thread; solve() checks it once per iteration and stops with StopReason::cancelled.
class CancelToken {
 public:
  void cancel() { cancelled_.store(true); }
  bool cancelled() const { return cancelled_.load(); }

 private:
  std::atomic<bool> cancelled_{false};
};

}  // namespace contact
