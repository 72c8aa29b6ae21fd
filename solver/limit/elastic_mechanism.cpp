#include "elastic_mechanism.hpp"

#include "mechanism.hpp"

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace contact::limit {

namespace {

using Velocity = Eigen::Vector3d;  // (vx, vy, omega) at a body's reference point

constexpr double kSliding = 0.5;    // a joint whose contact slips over this share of its force slides
constexpr double kStill = 0.1;      // a joint moving less than this of the largest joint's motion: shut
constexpr int kPasses = 20;         // rounds of the overlap's active set (each adds the rows that would overlap)
constexpr double kFringe = 1e-3;    // a row carrying less than this of its joint's force is not in its contact
constexpr double kHinge = 1.0 / 3;  // a joint whose contact spans at most this of its length turns about it
constexpr double kNoise = 1e-4;     // a body moving less than this of the largest (after scaling to 1): still
constexpr double kOverlap = 1e-3;   // an overlap rate above this (of the largest velocity, 1): not admissible

// 1. Each body's least-squares rigid motion of its increment, and the norms of that rigid part and of the increment
// (summed over the processes: the owners fit their bodies).
struct Fit {
  std::vector<Velocity> velocity;
  std::vector<double> rigid_norm2, norm2;
};

Fit rigid_fit(const ddm::ContactSystem& system, const RigidBlocks& blocks, const ddm::Displacements& before,
              const ddm::Displacements& after) {
  const size_t nb = blocks.bodies.size();
  std::vector<double> sums(5 * nb, 0.0);
  for (size_t a = 0; a < nb; ++a) {
    if (!system.runner().owns(a) || a >= after.size() || a >= before.size()) continue;
    const auto& nodes = system.problem().bodies[a].mesh.nodes;
    const Eigen::VectorXd& u1 = after[a];
    const Eigen::VectorXd& u0 = before[a];
    if (u1.size() != u0.size() || u1.size() < 2 * static_cast<Eigen::Index>(nodes.size())) continue;
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    double norm2 = 0.0;
    for (size_t i = 0; i < nodes.size(); ++i) {
      const Eigen::Index k = static_cast<Eigen::Index>(2 * i);
      const Eigen::Vector2d d = u1.segment<2>(k) - u0.segment<2>(k);
      const Eigen::Vector2d x = nodes[i] - blocks.bodies[a].reference;
      Eigen::Matrix<double, 2, 3> J;
      J << 1, 0, -x.y(), 0, 1, x.x();
      A += J.transpose() * J;
      b += J.transpose() * d;
      norm2 += d.squaredNorm();
    }
    const Velocity v = A.ldlt().solve(b);
    sums[5 * a] = v[0];
    sums[5 * a + 1] = v[1];
    sums[5 * a + 2] = v[2];
    sums[5 * a + 3] = v.dot(A * v);
    sums[5 * a + 4] = norm2;
  }
  system.runner().sum(sums.data(), sums.size());
  Fit fit;
  for (size_t a = 0; a < nb; ++a) {
    fit.velocity.emplace_back(sums[5 * a], sums[5 * a + 1], sums[5 * a + 2]);
    fit.rigid_norm2.push_back(sums[5 * a + 3]);
    fit.norm2.push_back(sums[5 * a + 4]);
  }
  return fit;
}

// Pair k at the held state: its rows, which of them are in contact (positive pressure) and which of those slip,
// and the point its pressure's resultant passes through (NaN without one).
struct Joint {
  std::vector<const JointRow*> rows, contact;
  double extent = 0.0;        // the largest distance between two of its rows
  double contact_span = 0.0;  // the largest distance between two of its rows in contact
  double slipping = 0.0;      // the share of its normal force on nodes that slip; 1 without friction
  bool friction = false;
  double tangential_force = 0.0;  // the master's friction force on the slave along the pair's tangent
  Eigen::Vector2d pressure_centre = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
};

double span(const std::vector<const JointRow*>& rows) {
  double out = 0.0;
  for (const auto* r : rows)
    for (const auto* q : rows) out = std::max(out, (q->point - r->point).norm());
  return out;
}

std::vector<Joint> joints_of(const ddm::ContactSystem& system, const RigidBlocks& blocks, const Step& held) {
  std::vector<Joint> joints(system.pairs().size());
  for (const auto& r : blocks.rows) joints[r.pair].rows.push_back(&r);
  for (size_t k = 0; k < joints.size(); ++k) {
    Joint& j = joints[k];
    j.extent = span(j.rows);
    const PairField* pair = nullptr;
    for (const auto& p : held.pairs)
      if (p.name == system.pairs()[k].name) pair = &p;
    if (!pair) continue;
    const bool friction = pair->friction != "none" && pair->stick.size() == pair->node.size();
    j.friction = friction;
    j.tangential_force = pair->tangential_force;
    // The rows that carry a share of its force worth a name (a node's pressure at 0.1 % of the force is an elastic
    // fringe of the contact, not where it bears), and of that force the share that slips.
    double N = 0.0, slipping = 0.0;
    Eigen::Vector2d moment = Eigen::Vector2d::Zero();
    std::vector<std::pair<const JointRow*, Eigen::Index>> carrying;
    std::unordered_map<int, Eigen::Index> entry;  // slave node -> its entry in the pair's fields
    for (Eigen::Index i = 0; i < pair->node.size(); ++i) entry.emplace(pair->node[i], i);
    for (const auto* r : j.rows) {
      const auto found = entry.find(r->node);
      if (found == entry.end()) continue;
      const Eigen::Index i = found->second;
      if (!(pair->weight[i] > 0) || !(pair->pressure[i] > 0)) continue;
      carrying.emplace_back(r, i);
      N += pair->weight[i] * pair->pressure[i];
    }
    double carried = 0.0;
    for (const auto& [r, i] : carrying) {
      const double f = pair->weight[i] * pair->pressure[i];
      if (f < kFringe * N) continue;
      j.contact.push_back(r);
      carried += f;
      moment += f * pair->position.row(i).transpose();
      if (!friction || pair->stick[i] == 0) slipping += f;
    }
    if (carried > 0) j.pressure_centre = moment / carried;
    j.contact_span = span(j.contact);
    j.slipping = N > 0 ? slipping / N : 0.0;
  }
  return joints;
}

// A linear constraint on the bodies' velocities: coefficients on (vx, vy, omega) of two bodies.
struct Constraint {
  int s = 0, t = 0;
  Velocity on_s = Velocity::Zero(), on_t = Velocity::Zero();
};

// The coefficients of a body's velocity at x along e.
Velocity along(const Eigen::Vector2d& e, const Eigen::Vector2d& reference, const Eigen::Vector2d& x) {
  const Eigen::Vector2d d = x - reference;
  return {e.x(), e.y(), -e.x() * d.y() + e.y() * d.x()};
}

Eigen::Vector2d relative_at(const RigidBlocks& blocks, const std::vector<Velocity>& v, int s, int t,
                            const Eigen::Vector2d& x) {
  const auto& bs = blocks.bodies[static_cast<size_t>(s)];
  const auto& bt = blocks.bodies[static_cast<size_t>(t)];
  return velocity_at(v[static_cast<size_t>(s)], bs.reference, x) -
         velocity_at(v[static_cast<size_t>(t)], bt.reference, x);
}

// 2. What each joint lets its bodies do, read off its contact set at the held state: nothing in contact, free (it
// may open); most of its contact slipping (or frictionless), sliding (no relative normal motion where it touches);
// its contact gathered in a short part of it, a hinge there (no relative motion at the row nearest the centre of
// pressure, where the thrust passes); else shut (no relative motion).
std::vector<Constraint> constraints_of(const RigidBlocks& blocks, const std::vector<Joint>& joints,
                                       const std::vector<Velocity>& fit, double still_below) {
  // How much each joint moves under the fitted motion: its largest relative velocity over its rows.
  std::vector<double> moves(joints.size(), 0.0);
  for (size_t k = 0; k < joints.size(); ++k)
    for (const auto* r : joints[k].rows)
      moves[k] = std::max(moves[k],
                          relative_at(blocks, fit, blocks.slave_of_pair[k], blocks.master_of_pair[k], r->point).norm());
  const double largest = moves.empty() ? 0.0 : *std::max_element(moves.begin(), moves.end());
  std::vector<Constraint> out;
  for (size_t k = 0; k < joints.size(); ++k) {
    const Joint& j = joints[k];
    if (j.contact.empty()) continue;
    // A joint whose contact gathers at a point but that the increment hardly moves is shut: it bears near its edge
    // (an arch's joints off the thrust line's hinges do), but it does not turn.
    const bool still = moves[k] <= still_below * largest;
    const int s = blocks.slave_of_pair[k], t = blocks.master_of_pair[k];
    const auto& rs = blocks.bodies[static_cast<size_t>(s)].reference;
    const auto& rt = blocks.bodies[static_cast<size_t>(t)].reference;
    auto relative_velocity_zero = [&](const Eigen::Vector2d& x, const Eigen::Vector2d& e) {
      out.push_back({s, t, along(e, rs, x), -along(e, rt, x)});
    };
    if (j.slipping >= kSliding) {
      for (const auto* r : j.contact) relative_velocity_zero(r->point, r->normal);
      continue;
    }
    if (!still && j.contact_span <= kHinge * j.extent && j.pressure_centre.allFinite()) {
      const JointRow* hinge = *std::min_element(j.contact.begin(), j.contact.end(), [&](auto* a, auto* b) {
        return (a->point - j.pressure_centre).norm() < (b->point - j.pressure_centre).norm();
      });
      relative_velocity_zero(hinge->point, Eigen::Vector2d::UnitX());
      relative_velocity_zero(hinge->point, Eigen::Vector2d::UnitY());
      continue;
    }
    const Eigen::Vector2d x = j.contact.front()->point;
    relative_velocity_zero(x, Eigen::Vector2d::UnitX());
    relative_velocity_zero(x, Eigen::Vector2d::UnitY());
    out.push_back({s, t, Velocity(0, 0, 1), Velocity(0, 0, -1)});
  }
  return out;
}

// 3. The fitted velocities projected onto the motions the constraints and the supports allow: in each body's
// admissible coordinates y (q = (vx, vy, size omega) = motions y), min |y - y_fit| subject to C y = 0, that is
// y = y_fit - C^T w with C C^T w = C y_fit (regularised: C may repeat itself; a second pass cleans the rest).
std::vector<Velocity> project(const RigidBlocks& blocks, const std::vector<Constraint>& constraints,
                              const std::vector<Velocity>& fit) {
  const size_t nb = blocks.bodies.size();
  std::vector<Eigen::Index> offset(nb + 1, 0);
  for (size_t a = 0; a < nb; ++a) offset[a + 1] = offset[a] + blocks.bodies[a].motions.cols();
  auto to_y = [&](size_t a, const Velocity& c) -> Eigen::VectorXd {  // a row on (vx, vy, omega) to one on y_a
    const Velocity q(c[0], c[1], c[2] / blocks.bodies[a].size);
    return blocks.bodies[a].motions.transpose() * q;
  };
  Eigen::VectorXd y(offset[nb]);
  for (size_t a = 0; a < nb; ++a) {
    const Velocity q(fit[a][0], fit[a][1], fit[a][2] * blocks.bodies[a].size);
    y.segment(offset[a], offset[a + 1] - offset[a]) = blocks.bodies[a].motions.transpose() * q;
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t i = 0; i < constraints.size(); ++i) {
    const auto& c = constraints[i];
    for (const auto& [body, coefficients] : {std::pair{c.s, c.on_s}, std::pair{c.t, c.on_t}}) {
      const size_t a = static_cast<size_t>(body);
      const Eigen::VectorXd row = to_y(a, coefficients);
      for (Eigen::Index j = 0; j < row.size(); ++j)
        if (row[j] != 0.0) entries.emplace_back(static_cast<int>(i), static_cast<int>(offset[a] + j), row[j]);
    }
  }
  if (!constraints.empty() && y.size() > 0) {
    Eigen::SparseMatrix<double> C(static_cast<Eigen::Index>(constraints.size()), y.size());
    C.setFromTriplets(entries.begin(), entries.end());
    Eigen::SparseMatrix<double> CCt = C * C.transpose();
    double trace = 0.0;
    for (Eigen::Index i = 0; i < CCt.rows(); ++i) trace += CCt.coeff(i, i);
    Eigen::SparseMatrix<double> I(CCt.rows(), CCt.cols());
    I.setIdentity();
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(CCt +
                                                              1e-12 * trace / static_cast<double>(CCt.rows()) * I);
    // (refined until the constraints hold to round-off: the regularisation leaves a little of C y behind each time)
    const double size = y.norm();
    for (int pass = 0; pass < 50 && solver.info() == Eigen::Success; ++pass) {
      const Eigen::VectorXd r = C * y;
      if (r.norm() <= 1e-12 * size) break;
      y -= C.transpose() * solver.solve(r);
    }
  }
  std::vector<Velocity> out(nb);
  for (size_t a = 0; a < nb; ++a) {
    const Velocity q = blocks.bodies[a].motions * y.segment(offset[a], offset[a + 1] - offset[a]);
    out[a] = Velocity(q[0], q[1], q[2] / blocks.bodies[a].size);
  }
  return out;
}

// Scaled so that the largest body's |v| + size |omega| is 1; bodies below kNoise of it are still. False when
// nothing moves, or less than `at_least` (what is left of a motion the constraints took away is round-off).
bool normalise(const RigidBlocks& blocks, std::vector<Velocity>& v, double at_least = 0.0) {
  double largest = 0.0;
  auto measure = [&](size_t a) { return v[a].head<2>().norm() + blocks.bodies[a].size * std::abs(v[a][2]); };
  for (size_t a = 0; a < v.size(); ++a) largest = std::max(largest, measure(a));
  if (!(largest > at_least) || !std::isfinite(largest)) return false;
  for (size_t a = 0; a < v.size(); ++a)
    v[a] = measure(a) < kNoise * largest ? Velocity::Zero() : Velocity(v[a] / largest);
  return true;
}

// The check: no joint overlaps, sliding joints slide against their friction, the loads being raised (`live`: a
// collapse analysis's live loads at multiplier 1, or a failed step's increment) do positive work.
std::string check(const ddm::ContactSystem& system, const RigidBlocks& blocks, const std::vector<Velocity>& v,
                  const Mechanism& m, const Step& held, const std::vector<Resultant>& live, bool& admissible) {
  admissible = false;
  if (m.bodies.empty()) return "no body moves";
  for (const auto& r : blocks.rows) {
    const int s = blocks.slave_of_pair[r.pair], t = blocks.master_of_pair[r.pair];
    const double opening = -relative_at(blocks, v, s, t, r.point).dot(r.normal);  // the slave's outward normal
    if (opening < -kOverlap)
      return "joint '" + system.pairs()[r.pair].name + "' would overlap at " + shown(r.point) + " (rate " +
             shown(-opening) + ")";
  }
  for (const auto& j : m.joints) {
    if (j.kind != "slides" && j.kind != "opens and slides") continue;
    for (const auto& pair : held.pairs)
      if (pair.name == j.pair && pair.friction != "none" && pair.tangential_force * j.slip > 0 &&
          std::abs(j.slip) > kOverlap)  // (the tolerance exact_motion holds rows to: a slip below it is round-off)
        return "joint '" + j.pair + "' would slide the way its friction pushed it (tangential force " +
               shown(pair.tangential_force) + ", slip " + shown(j.slip) + ")";
  }
  double work = 0.0;
  for (size_t a = 0; a < v.size() && a < live.size(); ++a) work += live[a].dot(v[a]);
  if (!(work > 0)) return "the loads being raised would do no positive work on it (" + shown(work) + ")";
  admissible = true;
  return "admissible: no joint overlaps, the sliding joints slide against their friction, the loads being raised do "
         "positive work on it (" +
         shown(work) + ")";
}

// The cosine between two motions of the bodies, each body's (vx, vy, size omega) one block of the vectors.
double cosine(const RigidBlocks& blocks, const std::vector<Velocity>& a, const std::vector<Velocity>& b) {
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    const Velocity L(1.0, 1.0, blocks.bodies[i].size);
    const Velocity x = a[i].cwiseProduct(L), y = b[i].cwiseProduct(L);
    ab += x.dot(y);
    aa += x.squaredNorm();
    bb += y.squaredNorm();
  }
  return aa > 0 && bb > 0 ? ab / std::sqrt(aa * bb) : 0.0;
}

// 3b. The exact motion for the joints' classes at `still`: the projection keeps the joints' equalities; a row the
// result would make overlap, or slip the way its friction pushed, is held too, and the fit projected again until
// no row does (or kPasses rounds). False when nothing is left moving.
bool exact_motion(const RigidBlocks& blocks, const std::vector<Joint>& joints, const std::vector<Velocity>& fitted,
                  double still, std::vector<Velocity>& v) {
  std::vector<Constraint> constraints = constraints_of(blocks, joints, fitted, still);
  for (int pass = 0; pass < kPasses; ++pass) {
    v = project(blocks, constraints, fitted);
    if (!normalise(blocks, v, 1e-6)) return false;  // (the fitted motion is scaled to 1)
    const size_t before = constraints.size();
    for (const auto& r : blocks.rows) {
      const int s = blocks.slave_of_pair[r.pair], t = blocks.master_of_pair[r.pair];
      const auto hold = [&](const Eigen::Vector2d& e) {
        constraints.push_back({s, t, along(e, blocks.bodies[static_cast<size_t>(s)].reference, r.point),
                               -along(e, blocks.bodies[static_cast<size_t>(t)].reference, r.point)});
      };
      const Eigen::Vector2d d = relative_at(blocks, v, s, t, r.point);
      if (-d.dot(r.normal) < -kOverlap) hold(r.normal);
      // A frictional joint in contact slides only against the friction it carried (else its friction would drive
      // the motion): a row that would slip the other way is held from slipping.
      const Joint& j = joints[r.pair];
      const bool in_contact = std::find(j.contact.begin(), j.contact.end(), &r) != j.contact.end();
      if (j.friction && in_contact && j.tangential_force * d.dot(r.tangent) > kOverlap * std::abs(j.tangential_force))
        hold(r.tangent);
    }
    if (constraints.size() == before) break;
  }
  return true;
}

}  // namespace

ElasticMechanism elastic_mechanism(const ddm::ContactSystem& system, const RigidBlocks& blocks,
                                   const ddm::Displacements& before, const ddm::Displacements& after, const Step& held,
                                   const std::vector<Resultant>& live) {
  ElasticMechanism out;
  const Fit fit = rigid_fit(system, blocks, before, after);
  std::vector<Velocity> fitted = fit.velocity;
  if (!normalise(blocks, fitted)) {
    out.check = "the last two held states do not differ";
    return out;
  }
  double rigid = 0.0, total = 0.0;
  for (size_t a = 0; a < fitted.size(); ++a)
    if (fitted[a] != Velocity::Zero()) {
      rigid += fit.rigid_norm2[a];
      total += fit.norm2[a];
    }
  out.rigid_share = total > 0 ? std::sqrt(rigid / total) : 0.0;
  const std::vector<Joint> joints = joints_of(system, blocks, held);
  // The fewest hinges first: a hinge that the increment turns little may still be one the mechanism needs (the last
  // of an arch's four forms late), so while the joints leave nothing moving the threshold is lowered.
  out.check = "the joints' contact sets leave no rigid motion";
  for (double still = kStill; still >= kStill / 64; still /= 2) {
    std::vector<Velocity> v;
    if (!exact_motion(blocks, joints, fitted, still, v)) continue;
    out.mechanism = describe_mechanism(system, blocks, v);
    out.mechanism.source = "elastic";
    out.kept = cosine(blocks, v, fitted);
    out.check = check(system, blocks, v, out.mechanism, held, live, out.admissible);
    out.mechanism.check = out.check;
    if (out.admissible) {
      out.mechanism.check += "; the increment into the last held state is " + shown(100 * out.rigid_share) +
                             " % rigid in the bodies that move, and the mechanism is its rigid part to a cosine of " +
                             shown(out.kept);
      break;
    }
  }
  return out;
}

}  // namespace contact::limit
