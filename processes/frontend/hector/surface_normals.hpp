// The direction of the surface under each point of a scan, from its neighbours along the scan,
// for matching a point only across its surface (scan_matcher.hpp, MatcherConfig::
// normal_projection).
//
// Why: a map's gradient also has parts along a surface, where the map is not the surface but
// its history: a wall's cells end where the map has seen it so far (the scanner sees further
// ahead than the map holds until its next update), a far wall seen at grazing incidence is a
// dotted line of cells one beam apart, and a cell sits up to half a cell off the wall it holds.
// Each part pulls the scan along the wall. Across a room such pulls cancel; along a bare
// corridor nothing else acts on the axis, and they decide it: a corridor scan matched against
// the map its own pose made slides by decimetres (tests/frontend/scan_matcher_test.cpp). Taking
// of the gradient only its part along the point's own surface normal (as point-to-plane ICP
// measures only across the plane) leaves the axis to what does show it (an end wall, a recess)
// and to the motion prior.
//
// A point's normal comes from a line fitted (principal axes) through it and its neighbours along
// the scan: outwards on each side until one lies 0.1 m away (range noise of millimetres then
// tilts the line by about a degree; a normal from the next few points alone tilts by tens of
// degrees and puts part of a wall's gradient on its axis), none beyond max(0.3 m, 10 % of the
// range) (a far wall seen at grazing incidence has its returns a metre apart). None (zero) where
// fewer than three points remain or the fit is not line-like (a corner, a depth jump, clutter:
// the smaller spread above a third of the larger); such a point keeps its whole gradient.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace traverse::frontend {

// Unit normals (or zero, see the header) of points ordered along a scan, in their frame; the
// scanner at `origin`, and each normal turned towards it.
std::vector<Eigen::Vector2d> surface_normals(
    const std::vector<Eigen::Vector2d>& points,
    const Eigen::Vector2d& origin = Eigen::Vector2d::Zero());

}  // namespace traverse::frontend
