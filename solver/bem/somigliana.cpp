// Somigliana's identities at interior points (kelvin.hpp for the kernels):
//   u_l(xi) = int U_lj t_j - int T_lj u_j,      sigma_ij(xi) = int D_kij t_k - int S_kij u_k,
// with the boundary displacement linear and the traction linear on each element. Every element is integrated
// by integrate_adaptively(), which halves pieces until each is no longer than its distance to xi: a point at
// distance d from an element costs ~log2(L / d) levels, and the error stays at the Gauss rules' ~1e-12 level
// relative to the kernels' size, so the result is as accurate as the boundary data close to the boundary too.
#include "bem.hpp"
#include "boundary.hpp"
#include "kelvin.hpp"
#include "quadrature.hpp"

namespace contact::bem {

namespace {

class Somigliana {
 public:
  Somigliana(const BoundaryProblem& problem, const BoundarySolution& solution)
      : geometry_(check_problem(problem, /*self_overlap=*/false)),
        kelvin_(effective_constants(problem.material), log_scale(geometry_)),
        solution_(solution) {
    check_solution(problem, solution);
  }

  Eigen::Vector2d displacement(const Eigen::Vector2d& xi) const {
    check_interior_point(geometry_, xi);
    Eigen::Vector2d u = Eigen::Vector2d::Zero();
    for_each_element(xi, [&](const BoundaryElement& el, const Eigen::Vector2d& r, const Eigen::Vector2d& u_x,
                             const Eigen::Vector2d& t_x, double w) {
      u += w * (kelvin_.displacement(r) * t_x - kelvin_.traction(r, el.normal) * u_x);
    });
    return u;
  }

  Eigen::Vector3d stress(const Eigen::Vector2d& xi) const {
    check_interior_point(geometry_, xi);
    Eigen::Vector3d sigma = Eigen::Vector3d::Zero();
    for_each_element(xi, [&](const BoundaryElement& el, const Eigen::Vector2d& r, const Eigen::Vector2d& u_x,
                             const Eigen::Vector2d& t_x, double w) {
      sigma += w * (kelvin_.stress_by_traction(r) * t_x - kelvin_.stress_by_displacement(r, el.normal) * u_x);
    });
    return sigma;
  }

 private:
  // Calls add(element, r = x - xi, u(x), t(x), weight) at the quadrature points of every element.
  template <class Add>
  void for_each_element(const Eigen::Vector2d& xi, Add&& add) const {
    const auto n = static_cast<Eigen::Index>(geometry_.elements.size());
    for (Eigen::Index e = 0; e < n; ++e) {
      const BoundaryElement& el = geometry_.elements[static_cast<std::size_t>(e)];
      const Eigen::Vector2d u0 = solution_.displacement.row(e).transpose();
      const Eigen::Vector2d u1 = solution_.displacement.row((e + 1) % n).transpose();
      const Eigen::Matrix2d& t = solution_.traction[static_cast<std::size_t>(e)];
      integrate_adaptively(el.start, el.tangent, 0.0, el.length, xi, [&](double s, double w) {
        const double n1 = s / el.length, n0 = 1.0 - n1;
        add(el, Eigen::Vector2d(el.start + s * el.tangent - xi), Eigen::Vector2d(n0 * u0 + n1 * u1),
            Eigen::Vector2d(n0 * t.col(0) + n1 * t.col(1)), w);
      });
    }
  }

  BoundaryGeometry geometry_;
  KelvinSolution kelvin_;
  const BoundarySolution& solution_;
};

}  // namespace

Eigen::Vector3d interior_stress(const BoundaryProblem& problem, const BoundarySolution& solution,
                                const Eigen::Vector2d& x) {
  return Somigliana(problem, solution).stress(x);
}

Eigen::Vector2d interior_displacement(const BoundaryProblem& problem, const BoundarySolution& solution,
                                      const Eigen::Vector2d& x) {
  return Somigliana(problem, solution).displacement(x);
}

Eigen::MatrixX3d interior_stresses(const BoundaryProblem& problem, const BoundarySolution& solution,
                                   const std::vector<Eigen::Vector2d>& points) {
  const Somigliana somigliana(problem, solution);
  Eigen::MatrixX3d stresses(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t k = 0; k < points.size(); ++k)
    stresses.row(static_cast<Eigen::Index>(k)) = somigliana.stress(points[k]).transpose();
  return stresses;
}

}  // namespace contact::bem
