// A static kd-tree over fixed-dimension Eigen vectors (nanoflann), for point neighbourhoods (3-D)
// and nearest neighbours in feature space (FPFH, 33-D). It keeps a reference to the data, which
// must outlive it and not change.
#pragma once

#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

#include <nanoflann.hpp>

namespace livo {

template <class Vector, class Container = std::vector<Vector>>
class KdTree {
 public:
  using Scalar = typename Vector::Scalar;
  static constexpr int kDim = Vector::RowsAtCompileTime;

  explicit KdTree(const Container& data, int leaf_size = 10)
      : adaptor_{data}, index_(kDim, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(leaf_size)) {
    if (!data.empty()) index_.buildIndex();
  }

  size_t size() const { return adaptor_.data.size(); }

  /// Up to k nearest neighbours, nearest first; returns how many were found.
  size_t knn(const Vector& query, size_t k, size_t* indices, Scalar* squared_distances) const {
    if (size() == 0 || k == 0) return 0;
    return index_.knnSearch(query.data(), k, indices, squared_distances);
  }

  /// The nearest neighbour; false if the tree is empty.
  bool nearest(const Vector& query, size_t& index, Scalar& squared_distance) const {
    return knn(query, 1, &index, &squared_distance) == 1;
  }

  /// The nearest point closer than sqrt(max_squared_distance); false if there is none. Cheaper than
  /// nearest() for queries far from the data: the search never looks beyond the bound.
  bool nearestWithin(const Vector& query, Scalar max_squared_distance, size_t& index, Scalar& squared_distance) const {
    if (size() == 0) return false;
    BoundedNearest result(max_squared_distance);
    index_.findNeighbors(result, query.data(), nanoflann::SearchParams());
    if (!result.found) return false;
    index = result.index;
    squared_distance = result.distance;
    return true;
  }

  /// Every point within `radius` (not squared) with its squared distance, nearest first if `sorted`.
  size_t radius(const Vector& query, Scalar radius, std::vector<std::pair<size_t, Scalar>>& out,
                bool sorted = true) const {
    out.clear();
    if (size() == 0) return 0;
    return index_.radiusSearch(query.data(), radius * radius, out, nanoflann::SearchParams(32, 0.0f, sorted));
  }

 private:
  struct Adaptor {
    const Container& data;
    size_t kdtree_get_point_count() const { return data.size(); }
    Scalar kdtree_get_pt(size_t i, size_t d) const { return data[i][static_cast<int>(d)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  struct BoundedNearest {  // a nanoflann result set: one neighbour, searched only within a bound
    explicit BoundedNearest(Scalar bound) : distance(bound) {}
    Scalar distance;
    size_t index = 0;
    bool found = false;
    bool full() const { return found; }
    Scalar worstDist() const { return distance; }
    bool addPoint(Scalar d, size_t i) {
      if (d < distance) {
        distance = d;
        index = i;
        found = true;
      }
      return true;
    }
  };
  using Index =
      nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<Scalar, Adaptor>, Adaptor, kDim, size_t>;
  Adaptor adaptor_;
  Index index_;
};

}  // namespace livo
