// FETI's natural coarse space: the equilibrium of the floating bodies, G z = e (interface_problem.hpp), three rows
// (two in a body held sideways at a point) per body that only its contacts hold. G couples a body's rows to its
// own contact nodes only, so G G^T is a sparse r x r matrix (a body to its neighbours), factorised once per
// interface problem; it is the only thing every process holds whole.
//
//   Q = G^T (G G^T)^-1 G   the orthogonal projector onto the range of G^T (the rigid motions' gaps),
//   P = I - Q              the projector onto ker G (pressures in equilibrium with no load),
//   z_I = G^T (G G^T)^-1 e the least-squares pressures that balance the floating bodies' loads.
// With them the iterative interface solver works in ker G, where the interface operator's spectrum is bounded
// by the bodies' size over the mesh size and not by their number (Farhat, Mandel & Roux 1994; Dostal et al.'s
// TFETI): the reason the iterations do not grow with the number of bodies.
#pragma once

#include "interface_problem.hpp"

#include <memory>

namespace contact::ddm {

class CoarseSpace {
 public:
  // Factorises G G^T. ok() is false when some floating body's rows are dependent (its contacts cannot hold all of
  // its rigid motions whatever the pressures): unheld() lists those rows.
  CoarseSpace(const InterfaceProblem& problem, const Equalities& equilibrium);
  ~CoarseSpace();
  CoarseSpace(const CoarseSpace&) = delete;
  CoarseSpace& operator=(const CoarseSpace&) = delete;

  bool ok() const { return unheld_.empty(); }
  const std::vector<Eigen::Index>& unheld() const { return unheld_; }
  bool empty() const { return G_.rows() == 0; }
  Eigen::Index rows() const { return G_.rows(); }

  Eigen::VectorXd project(const Eigen::VectorXd& x) const;     // P x
  Eigen::VectorXd range_part(const Eigen::VectorXd& x) const;  // Q x
  Eigen::VectorXd particular() const;                          // z_I
  // The least-squares multipliers alpha of G^T alpha = -r on the columns `columns` (the active contact nodes):
  // (G_A G_A^T)^-1 G_A (-r_A). Empty when G_A G_A^T is singular (the active set leaves a body unheld), unless
  // `indeterminate` allows it: then the least-squares solution with the least |alpha| along the motions no column
  // holds (G_A G_A^T + eps I, eps = 1e-10 of its largest diagonal entry), the choice the direct solver makes for
  // a brick whose joints all slip (linalg/friction_nested.cpp, solve_sets_system). With `prior`, the solution
  // nearest to it along those motions instead of the least (the QP's own equality multipliers, which make every
  // slip point the way its friction force resists: Smalbe::finish).
  Eigen::VectorXd multipliers(const Eigen::VectorXd& r, const std::vector<char>& columns, bool indeterminate = false,
                              const Eigen::VectorXd* prior = nullptr) const;
  // (G G^T)^-1 v.
  Eigen::VectorXd solve_GGt(const Eigen::VectorXd& v) const;
  // The rows of the floating bodies that the columns `columns` alone cannot hold (their block of G_A G_A^T is
  // singular): the bodies an active set leaves unheld.
  std::vector<Eigen::Index> unheld_by(const std::vector<char>& columns) const;
  // The coarse space of a face: G_F, the columns `columns` of G (the contact rows strictly inside their bounds),
  // with G_F G_F^T factorised. Serves the equality-constrained QP on a settled face (Smalbe::solve_face).
  class Face {
   public:
    // false: G_F G_F^T is singular (the face leaves some rigid motion free), or there is no G at all (no floating
    // body: SMALBE has no equalities and ends with its first inner solve, before a face solve would start).
    bool ok() const { return ok_; }
    // v - G_F^T (G_F G_F^T)^-1 G_F v: the part of v (zero off the face) in ker G_F.
    Eigen::VectorXd project(const Eigen::VectorXd& v) const;
    // G_F^T (G_F G_F^T)^-1 r: the least change on the face that changes G z by r.
    Eigen::VectorXd correction(const Eigen::VectorXd& r) const;
    // -(G_F G_F^T)^-1 G_F h: the multipliers alpha that make h + G^T alpha orthogonal to range G_F^T.
    Eigen::VectorXd multipliers(const Eigen::VectorXd& h) const;
    ~Face();

   private:
    friend class CoarseSpace;
    Face() = default;
    struct Factor;
    SparseMatrix GF_, GFt_;
    std::unique_ptr<Factor> factor_;
    bool ok_ = false;
  };
  std::unique_ptr<Face> face(const std::vector<char>& columns) const;
  const SparseMatrix& G() const { return G_; }
  const Eigen::VectorXd& e() const { return e_; }

 private:
  struct Factor;
  SparseMatrix columns_of(const std::vector<char>& columns) const;

  const InterfaceProblem& problem_;
  SparseMatrix G_, Gt_;
  Eigen::VectorXd e_;
  std::unique_ptr<Factor> factor_;
  std::vector<Eigen::Index> unheld_;
};

}  // namespace contact::ddm
