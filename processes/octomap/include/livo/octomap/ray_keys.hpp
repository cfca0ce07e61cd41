// The voxel keys a ray passes through on the way to its end, as octomap's
// OcTreeBaseImpl::computeRayKeys lists them (the same keys in the same order: the same 3D DDA of
// Amanatides & Woo with the same float/double arithmetic, so the map is the same), handed to a
// callback instead of being gathered into a KeyRay, and with the origin's key given (a sweep slice
// casts all its rays from one origin). tests/octomap/test_octomap_core.cpp checks it against
// computeRayKeys over random rays.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <octomap/OcTree.h>

namespace livo::octomap {

/// Walks the voxels between origin (whose key is origin_key) and end: walker.start(origin_key)
/// for the origin's voxel, then walker.template step<A>(dir, key) for each further voxel, the key
/// having moved by dir (+1 or -1) along axis A from the one before (a DDA step changes one axis:
/// a caller can address the voxel incrementally); the end's voxel is not walked, and nothing at all
/// when both are one voxel. False (and no calls) when end lies outside the tree's key range, as
/// computeRayKeys. The keys are computeRayKeys' keys in its order.
template <class Walker>
bool walkRayKeys(const ::octomap::OcTree& keys, const ::octomap::point3d& origin,
                 const ::octomap::OcTreeKey& origin_key, const ::octomap::point3d& end, Walker&& walker) {
  ::octomap::OcTreeKey end_key;
  if (!keys.coordToKeyChecked(end, end_key)) return false;
  if (end_key == origin_key) return true;
  walker.start(origin_key);

  ::octomap::point3d dir = end - origin;
  const float length = static_cast<float>(dir.norm());
  dir /= length;
  const double res = keys.getResolution();
  int step[3];
  double t_next[3];   // ray length at which the ray leaves the current voxel along each axis
  double t_delta[3];  // ray length across one voxel along each axis
  for (int a = 0; a < 3; ++a) {
    const float da = dir(a);
    if (da == 0.0f) {
      step[a] = 0;
      t_next[a] = t_delta[a] = std::numeric_limits<double>::max();
      continue;
    }
    step[a] = da > 0.0f ? 1 : -1;
    double border = keys.keyToCoord(origin_key[a]);
    border += static_cast<float>(step[a] * res * 0.5);
    t_next[a] = (border - origin(a)) / da;
    t_delta[a] = res / std::fabs(da);
  }

  // the walk in scalars (registers): the axis whose voxel border comes first is stepped (ties go
  // to the later axis, as octomap breaks them); the walk ends on meeting the end's voxel (not
  // visited) or, if rounding made it miss that voxel, once the next border lies past the end
  double tx = t_next[0], ty = t_next[1], tz = t_next[2];
  const double dx = t_delta[0], dy = t_delta[1], dz = t_delta[2];
  const int sx = step[0], sy = step[1], sz = step[2];
  unsigned kx = origin_key[0], ky = origin_key[1], kz = origin_key[2];
  const unsigned ex = end_key[0], ey = end_key[1], ez = end_key[2];
  const double len = length;
  // each branch ends in its own check and call: the stepped axis is known there at compile time
  auto done = [&] { return (kx == ex && ky == ey && kz == ez) || std::min(std::min(tx, ty), tz) > len; };
  auto key = [&] {
    return ::octomap::OcTreeKey(static_cast<::octomap::key_type>(kx), static_cast<::octomap::key_type>(ky),
                                static_cast<::octomap::key_type>(kz));
  };
  while (true) {
    if (tx < ty) {
      if (tx < tz) {
        kx = (kx + unsigned(sx)) & 0xFFFFu;
        tx += dx;
        if (done()) return true;
        walker.template step<0>(sx, key());
        continue;
      }
    } else if (ty < tz) {
      ky = (ky + unsigned(sy)) & 0xFFFFu;
      ty += dy;
      if (done()) return true;
      walker.template step<1>(sy, key());
      continue;
    }
    kz = (kz + unsigned(sz)) & 0xFFFFu;
    tz += dz;
    if (done()) return true;
    walker.template step<2>(sz, key());
  }
}

namespace detail {
template <class Visit>
struct KeyWalker {  // the walk as keys only
  Visit& visit;
  void start(const ::octomap::OcTreeKey& k) { visit(k); }
  template <int A>
  void step(int, const ::octomap::OcTreeKey& k) {
    visit(k);
  }
};
}  // namespace detail

/// Calls visit(key) for each voxel between origin (whose key is origin_key) and end: the origin's
/// voxel first, the end's voxel not (nothing at all when both are one voxel). False (and no
/// calls) when end lies outside the tree's key range, as computeRayKeys.
template <class Visit>
bool forEachRayKey(const ::octomap::OcTree& keys, const ::octomap::point3d& origin,
                   const ::octomap::OcTreeKey& origin_key, const ::octomap::point3d& end, Visit&& visit) {
  detail::KeyWalker<Visit> w{visit};
  return walkRayKeys(keys, origin, origin_key, end, w);
}

}  // namespace livo::octomap
