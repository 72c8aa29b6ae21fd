#include "mechanism.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace contact::limit {

std::string shown(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", std::abs(value) < 1e-12 ? 0.0 : value);
  return text;
}

std::string shown(const Eigen::Vector2d& point) { return "(" + shown(point.x()) + ", " + shown(point.y()) + ")"; }

namespace {

constexpr double kStill = 1e-6;    // a body or joint whose velocity is below this (of the largest, 1) does not move
constexpr double kTurning = 1e-3;  // a relative motion turns when |omega| x extent is above this of its velocity

std::string joined(const std::vector<std::string>& parts, size_t at_most) {
  std::string out;
  for (size_t i = 0; i < parts.size() && i < at_most; ++i) out += (i ? "; " : "") + parts[i];
  if (parts.size() > at_most) out += "; and " + std::to_string(parts.size() - at_most) + " more";
  return out;
}

// The body's motion as a verb phrase ("translates along (1, 0)", "turns clockwise about (1, 0)"; plural: "translate",
// "turn"), and its centre if it turns.
std::string motion_phrase(const RigidBody& body, const Eigen::Vector3d& v, bool plural, Eigen::Vector2d* centre) {
  const Eigen::Vector2d velocity = v.head<2>();
  if (body.size * std::abs(v[2]) <= kTurning * velocity.norm())
    return std::string(plural ? "translate" : "translates") + " along " + shown(Eigen::Vector2d(velocity.normalized()));
  const Eigen::Vector2d c = body.reference + Eigen::Vector2d(-v[1] / v[2], v[0] / v[2]);
  if (centre) *centre = c;
  return std::string(plural ? "turn " : "turns ") + (v[2] < 0 ? "clockwise" : "anticlockwise") + " about " + shown(c);
}

BodyMotion body_motion(const RigidBody& body, const Eigen::Vector3d& v) {
  BodyMotion m;
  m.body = body.name;
  m.velocity = v.head<2>();
  m.omega = v[2];
  m.reference = body.reference;
  m.words = "body '" + body.name + "' " + motion_phrase(body, v, false, &m.centre);
  return m;
}

// What pair k does under the mechanism, if it moves.
bool joint_motion(const ddm::ContactSystem& system, const RigidBlocks& blocks,
                  const std::vector<Eigen::Vector3d>& velocity, size_t k, JointMotion& out) {
  const size_t s = static_cast<size_t>(blocks.slave_of_pair[k]), t = static_cast<size_t>(blocks.master_of_pair[k]);
  std::vector<const JointRow*> rows;
  for (const auto& r : blocks.rows)
    if (r.pair == k) rows.push_back(&r);
  if (rows.empty()) return false;
  auto relative = [&](const Eigen::Vector2d& x) {
    return Eigen::Vector2d(velocity_at(velocity[s], blocks.bodies[s].reference, x) -
                           velocity_at(velocity[t], blocks.bodies[t].reference, x));
  };
  double scale = 0.0, extent = 0.0, largest_slip = 0.0;
  Eigen::Vector2d middle = Eigen::Vector2d::Zero();
  for (const auto* r : rows) {
    const Eigen::Vector2d d = relative(r->point);
    scale = std::max(scale, d.norm());
    out.opening = std::max(out.opening, -d.dot(r->normal));  // the normal is the slave's outward one
    largest_slip = std::max(largest_slip, std::abs(d.dot(r->tangent)));
    middle += r->point;
    for (const auto* q : rows) extent = std::max(extent, (q->point - r->point).norm());
  }
  if (scale <= kStill) return false;
  middle /= static_cast<double>(rows.size());
  out.pair = system.pairs()[k].name;
  const double omega = velocity[s][2] - velocity[t][2];
  const Eigen::Vector2d at_middle = relative(middle);
  const JointRow& centre_row = **std::min_element(rows.begin(), rows.end(), [&](const JointRow* a, const JointRow* b) {
    return (a->point - middle).norm() < (b->point - middle).norm();
  });
  if (std::abs(omega) * std::max(extent, 1e-300) > kTurning * scale) {
    const Eigen::Vector2d c = middle + Eigen::Vector2d(-at_middle.y() / omega, at_middle.x() / omega);
    const JointRow* nearest = *std::min_element(rows.begin(), rows.end(), [&](const JointRow* a, const JointRow* b) {
      return (a->point - c).norm() < (b->point - c).norm();
    });
    if ((nearest->point - c).norm() <= 0.02 * extent + 1e-12 * blocks.bodies[s].size) {
      out.kind = "hinge";
      out.point = nearest->point;
      out.slip = 0.0;
      out.words = "joint '" + out.pair + "' opens as a hinge at " + shown(out.point);
      return true;
    }
    out.kind = "opens and slides";
    out.point = middle;
    out.slip = at_middle.dot(centre_row.tangent);
    out.words = "joint '" + out.pair + "' opens and slides, turning about " + shown(c);
    return true;
  }
  out.point = middle;
  out.slip = at_middle.dot(centre_row.tangent);
  if (largest_slip > kStill) {
    out.kind = "slides";
    const Eigen::Vector2d along = out.slip >= 0 ? centre_row.tangent : Eigen::Vector2d(-centre_row.tangent);
    out.words = "joint '" + out.pair + "' slides: '" + blocks.bodies[s].name + "' moves along " + shown(along) +
                " over '" + blocks.bodies[t].name + "'";
  } else {
    out.kind = "opens";
    out.words = "joint '" + out.pair + "' opens";
  }
  return true;
}

}  // namespace

Mechanism describe_mechanism(const ddm::ContactSystem& system, const RigidBlocks& blocks,
                             const std::vector<Eigen::Vector3d>& velocity) {
  Mechanism m;
  if (velocity.size() != blocks.bodies.size()) return m;
  std::vector<std::string> body_words, joint_words;
  // Bodies that move as one (the same rigid motion: one velocity field) are named together.
  std::vector<std::pair<size_t, std::vector<std::string>>> groups;  // (first body, names)
  for (size_t a = 0; a < blocks.bodies.size(); ++a) {
    const Eigen::Vector3d& v = velocity[a];
    if (v.head<2>().norm() + blocks.bodies[a].size * std::abs(v[2]) <= kStill) continue;
    m.bodies.push_back(body_motion(blocks.bodies[a], v));
    auto same = [&](const auto& g) {
      const size_t b = g.first;
      const Eigen::Vector2d at_b = velocity_at(v, blocks.bodies[a].reference, blocks.bodies[b].reference);
      return std::abs(v[2] - velocity[b][2]) * blocks.bodies[b].size <= kStill &&
             (at_b - velocity[b].head<2>()).norm() <= kStill;
    };
    auto it = std::find_if(groups.begin(), groups.end(), same);
    if (it == groups.end()) it = groups.insert(groups.end(), {a, {}});
    it->second.push_back(blocks.bodies[a].name);
  }
  for (const auto& [first, names] : groups) {
    const RigidBody& body = blocks.bodies[first];
    if (names.size() == 1) {
      body_words.push_back("body '" + names.front() + "' " + motion_phrase(body, velocity[first], false, nullptr));
      continue;
    }
    std::string list;
    for (size_t i = 0; i < names.size() && i < 8; ++i) list += (i ? ", '" : "'") + names[i] + "'";
    if (names.size() > 8) list += " and " + std::to_string(names.size() - 8) + " more";
    body_words.push_back("bodies " + list + " " + motion_phrase(body, velocity[first], true, nullptr) + " as one");
  }
  int hinges = 0, slides = 0;
  for (size_t k = 0; k < blocks.slave_of_pair.size(); ++k) {
    JointMotion j;
    if (!joint_motion(system, blocks, velocity, k, j)) continue;
    hinges += j.kind == "hinge";
    slides += j.kind == "slides";
    joint_words.push_back(j.words);
    m.joints.push_back(std::move(j));
  }
  if (m.bodies.empty()) return m;
  const int joints = static_cast<int>(m.joints.size());
  int opens = 0;
  for (const auto& j : m.joints) opens += j.kind == "opens";
  std::string why;
  if (joints == 0) {
    m.kind = "unsupported";
    why = " (no support and no contact pair holds them: a contact or a support is missing)";
  } else if (opens == joints) {
    m.kind = "lift-off";
    why = " (the loads pull them off their joints: is a load, or gravity, the wrong way?)";
  } else if (slides > 0 && slides + opens == joints) {
    m.kind = "sliding";  // (joints that only open besides: head joints parting as the courses slide)
  } else if (hinges == joints) {
    m.kind = hinges == 1 ? "overturning" : "hinging";
  } else if (groups.size() == 1 && !std::isnan(m.bodies.front().centre.x())) {
    m.kind = "overturning";  // one group turning as one about a point: over a stepped crack, about a toe
  } else {
    m.kind = "mixed";
  }
  m.words = m.kind + ": " + joined(body_words, 6) + why + (joint_words.empty() ? "" : "; " + joined(joint_words, 8));
  return m;
}

}  // namespace contact::limit
