// Where a slave edge ends against the rest of the problem: nodes whose normal displacement is prescribed (the
// crosspoints of docs/algorithm.md, "Edges of the contact surface"), and the corners where another contact edge of
// the same body meets the slave edge and friction would tie three bodies in a loop. Used by pair.cpp to classify the
// slave nodes; moved here from it unchanged.
#pragma once

#include "contact/problem.hpp"
#include "contact_index.hpp"

#include <Eigen/Core>

#include <array>
#include <map>
#include <vector>

namespace contact::mortar {

// Prescribed displacement components (x, y) of every node of a body.
std::map<int, std::array<bool, 2>> prescribed_components(const Body& body);

// A crosspoint: the node's displacement along its normal is prescribed (both components, or the one component
// within 10 degrees of the normal), so the slave side cannot move to open or close the contact there.
bool normal_is_prescribed(const std::array<bool, 2>& p, const Eigen::Vector2d& n);

// The end nodes of a slave edge where another contact edge of the same body meets it (a corner of the body where
// its joints turn: a brick's bottom and right edge, or the top of a head joint under the bed joint of the course
// above), with the other edge's unit tangent there, whether that edge is another pair's master edge facing a third
// body, and whether friction is involved (this pair's or the other's).
//
// Why: where three bodies meet at one point, each pair ties two of them there, and with friction the ties close a
// loop: at a brick's corner on a bed joint, the two bed joints' tangential rows and the head joint's normal row
// all tie the x-displacements of the same three bodies at one point, the two bed joints' normal rows and the head
// joint's tangential row their y-displacements. The multipliers are then redundant and the stick and slip systems
// singular (or nearly: pressures of 1e7 that cancel). The pair therefore drops, at such a corner, its tangential
// row (against another slave edge of the same body: the corner of the brick) or its multiplier altogether (against
// a master edge facing a third body: the top of a head joint), the crosspoint treatment of the dual mortar
// literature restricted to where friction makes it necessary. Frictionless contact has no such loop (its rows tie
// along the normals only) and is left as it was.
struct Corner {
  Eigen::Vector2d tangent = Eigen::Vector2d::Zero();
  bool third_body = false;  // the other edge is a master edge facing a body other than this pair's master
  bool friction = false;
};

// The corners at the ends of the slave edge `nodes` (its nodes in order) of `pair`; `index`: the problem's pairs
// by body.
std::map<int, Corner> slave_corners(const Problem& problem, const ContactIndex& index, const ContactPair& pair,
                                    const std::vector<int>& nodes, bool look_for_broken_loops = true);

// Whether the other edge turns away from this one at the node (more than 10 degrees between the tangents).
bool turns(const Eigen::Vector2d& own, const Eigen::Vector2d& other);

}  // namespace contact::mortar
