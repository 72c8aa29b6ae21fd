// Refinement that serves the contact (issue 20, item 2; docs/algorithm.md, "Marking that serves the contact").
//
// What an adaptive contact run is for is the contact pressure (and its resultant). Three rules on top of the
// indicator, all relative to the contact zones (the boxes of the pairs' nodes with a positive pressure):
//  * the band: a cell within its own size h of a zone has its indicator multiplied by sqrt(l / h), l the zone's
//    extent: the cells that carry the pressure are held to delta sqrt(h / l) instead of delta, a tolerance that
//    tightens as they shrink, so refinement follows the contact surface until its stress error falls faster than
//    sqrt(h) (where the pressure is smooth) or the level limit is reached (at the zone's edges);
//  * the neighbourhood (issue 30, item 1): a cell within one zone extent l of a zone is held to delta / 2 (factor 2
//    on its indicator, or the band's if larger). Why: the pressure, and above all the contact's width that its
//    square-root edges follow, is set by the stiffness of the body under and around the zone (Saint-Venant: the
//    stresses of a load of extent l are of its order within about l of it), not by the surface cells alone. With
//    delta alone every cell there stops at eta <= delta, and the error that leaves in the pressure is a floor the
//    band cannot lower: on the paper's test 0.45-0.5 % while the band refined the surface to level 7 and the
//    unknowns grew 4x (docs/algorithm.md, "What the plateau was"). The floor falls like delta^1.7, so the half
//    tolerance puts it below what the band and the edges reach in the steps the loop takes;
//  * the grading: a cell smaller than `grading` times its distance d to the nearest zone is not refined, whatever
//    its indicator. The influence of a cell's error on the contact is carried by the dual solution of a load on the
//    zone, whose second derivatives decay like 1/d^2 away from it; a mesh graded as h ~ alpha d resolves it with a
//    uniform relative accuracy, and refining below that (a clamped corner's singularity far from the contact, say)
//    adds unknowns that barely move the pressure.
#pragma once

#include "contact/mesh.hpp"
#include "contact/result.hpp"

#include <Eigen/Core>
#include <vector>

namespace contact::adapt {

// One contact zone: the box of a pair's nodes with a positive pressure.
struct ContactZone {
  Eigen::Vector2d lo, hi;
  double distance(const Eigen::Vector2d& x) const { return (lo - x).cwiseMax(x - hi).cwiseMax(0.0).norm(); }
  double extent() const { return (hi - lo).norm(); }
};

// The zones of a step's contact pairs (none where a pair carries no pressure).
std::vector<ContactZone> contact_zones(const Step& step);

// Per cell, the rules above: the factor on its indicator (1 outside the band and the neighbourhood) and whether
// the grading keeps it as it is. Without zones: factors 1, nothing kept.
struct ContactMarking {
  std::vector<double> factor;
  std::vector<char> graded;
};
ContactMarking contact_marking(const mesh::Mesh& mesh, const std::vector<ContactZone>& zones, double grading);

}  // namespace contact::adapt
