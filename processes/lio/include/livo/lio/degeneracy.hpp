// Degeneracy of a scan-to-map registration from the eigen-analysis of its information matrix.
//
// The test runs on a unit-free version of H^T H averaged over the m residuals, with the rotation
// columns divided by a reference lever arm L:  G = D H^T H D / m,  D = diag(I3 / L, I3). The LIO
// builds it from the rows whose planes stay planes with any one neighbour left out (plane.hpp): a
// line of floor points plus one wall point spans a plane that only that point chose, and in a
// corridor such planes would be the axis's only "evidence".
// Its translation block is the scatter of the plane normals (eigenvalues in [0, 1], summing to
// 1); its rotation block is the points' mean squared lever arm about each axis over L^2.
// A direction of either block with an eigenvalue below the threshold is degenerate: a corridor's
// axis has a translation eigenvalue near 0 (only range noise tilts the normals), a single plane
// leaves two translations and the rotation about its normal unconstrained.
//
// Solution remapping in information form: the degenerate directions (unit [rotation; translation]
// vectors e from each block's eigen-analysis) are marginalised out of the rows' information, so
// the update takes nothing along them from the LiDAR, noise included, and of the other directions
// only what holds wherever the pose lies along them; the prior (IMU, wheels) carries the state
// there. Projecting the rows off them instead (H' = H Q, Q = I - sum e e^T) keeps what a row
// measures jointly with the axis as if the position along it were known: in a featureless
// corridor (tests/lio, CorridorFlagsDegeneracyWithoutDiverging) the two or three rows a sweep has
// along it then tilt the attitude, the tilt leaks gravity into the acceleration along the axis,
// and a bias-free IMU ended 0.19 of the distance off where it now ends 0.04. Removing the eigenvector of the full 6x6 G
// is not enough: noisy normals couple the corridor's axis to a small rotation, and through the large rotational
// information of far points that leaves the axis centimetre-level "information".
#pragma once

#include "livo/so3.hpp"

namespace livo::lio {

struct DegeneracyReport {
  Vec3 rotation_eigenvalues = Vec3::Zero();        // ascending, of G's rotation block
  Vec3 translation_eigenvalues = Vec3::Zero();     // ascending, of G's translation block
  Mat3 rotation_directions = Mat3::Identity();     // columns: body-frame axes (right perturbation)
  Mat3 translation_directions = Mat3::Identity();  // columns: world-frame directions
  int degenerate_rotations = 0;                    // eigenvalues below the threshold, per block
  int degenerate_translations = 0;
  bool degenerate = false;
  Vec6 weakest_direction = Vec6::Zero();  // [rotation; translation] of the smallest eigenvalue
  double min_eigenvalue = 0.0;            // smallest of all six
};

/// geometry: G above; threshold on its block eigenvalues.
DegeneracyReport analyzeDegeneracy(const Mat6& geometry, double threshold);

/// Removes from S = H^T R^-1 H and g = H^T R^-1 z what the rows say along the degenerate
/// directions by marginalising them out (the Schur complement): the rest keeps only the
/// information that holds wherever the pose lies along those directions. Projecting them out
/// (Q S Q) would keep, say, the rotation a row measures only jointly with the corridor's axis,
/// as if the position along it were known; the few rows that see something along the axis (a
/// corner's plane, a normal tilted by noise) would then pull the attitude instead, and the tilt
/// leaks gravity into the acceleration along the axis.
void removeDegenerateInformation(const DegeneracyReport& report, Mat6* S, Vec6* g);

}  // namespace livo::lio
