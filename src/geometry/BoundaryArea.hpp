// The area vectors of a mesh's whole boundary at its corner nodes, a_I = int lambda_I n dA over
// the facets that belong to one element only, on the linear facets: a segment (2D) gives each
// end half its vector area, a triangle each corner a third, a quadrangle each corner a quarter
// of the vector area of its boundary loop. Every facet's vector area is that of a closed loop,
// so the a_I of a closed boundary sum to zero to rounding, as the integration constraint
// (method/IntegrationConstraint.hpp) needs.
//
// The first moments b_I = int lambda_I (X - X_I) (x) n dA, for the linear-stress constraint, on
// the same facets with the hats' products exact on each: a facet of area vector A_f adds
// w (X_J - X_I) (x) A_f for each other corner J, w = int lambda_I lambda_J dA / A: 1/6 on a
// segment, 1/12 on a triangle, on a parallelogram 1/18 for adjacent corners and 1/36 for
// opposite ones. With a_I they satisfy the divergence theorem for the linear fields:
// sum_I (b_I + X_I (x) a_I) = int X (x) n dA = Vol 1.
#pragma once

#include <algorithm>
#include <array>
#include <map>
#include <stdexcept>
#include <vector>

#include "model/Types.hpp"

namespace tlsph {

namespace detail {

// The faces of a 3D element by its corner count, in gmsh's corner order (tetrahedron, pyramid,
// prism, hexahedron); each face as a loop of corners.
inline std::vector<std::vector<int>> elementFaces(int corners) {
  switch (corners) {
    case 4:
      return {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    case 5:
      return {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
    case 6:
      return {{0, 2, 1}, {3, 4, 5}, {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}};
    case 8:
      return {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  }
  throw std::invalid_argument("an element with " + std::to_string(corners) + " corners");
}

}  // namespace detail

// cellStart / cellNode: the D-elements by their corner nodes (compressed rows). firstMoments:
// where to put the b_I too, or null.
template <int D>
std::vector<Vec<D>> boundaryAreaVectors(const std::vector<Vec<D>>& X,
                                        const std::vector<Index>& cellStart,
                                        const std::vector<Index>& cellNode,
                                        std::vector<Mat<D>>* firstMoments = nullptr) {
  // Each facet by its sorted corners: how often it occurs, and its loop oriented out of the
  // first element that has it.
  struct Facet {
    std::vector<Index> loop;
    int count = 0;
  };
  std::map<std::vector<Index>, Facet> facets;
  for (std::size_t c = 0; c + 1 < cellStart.size(); ++c) {
    const Index first = cellStart[c];
    const int corners = static_cast<int>(cellStart[c + 1] - first);
    Vec<D> centroid = Vec<D>::Zero();
    for (int q = 0; q < corners; ++q)
      centroid += X[cellNode[first + q]];
    centroid /= corners;
    std::vector<std::vector<int>> faces;
    if constexpr (D == 2) {
      for (int q = 0; q < corners; ++q)
        faces.push_back({q, (q + 1) % corners});
    } else {
      faces = detail::elementFaces(corners);
    }
    for (const auto& face : faces) {
      std::vector<Index> loop;
      Vec<D> middle = Vec<D>::Zero();
      for (int q : face) {
        loop.push_back(cellNode[first + q]);
        middle += X[loop.back()];
      }
      middle /= double(face.size());
      std::vector<Index> key = loop;
      std::sort(key.begin(), key.end());
      Facet& f = facets[key];
      if (f.count++ == 0) {
        f.loop = loop;
        // outward: away from the element's centroid
        Vec<D> a = Vec<D>::Zero();
        if constexpr (D == 2) {
          const Vec<2> t = X[loop[1]] - X[loop[0]];
          a = Vec<2>(t.y(), -t.x());
        } else {
          for (std::size_t q = 0; q < loop.size(); ++q)
            a += 0.5 * X[loop[q]].cross(X[loop[(q + 1) % loop.size()]]);
        }
        if (a.dot(middle - centroid) < 0.0) std::reverse(f.loop.begin(), f.loop.end());
      }
    }
  }
  std::vector<Vec<D>> area(X.size(), Vec<D>::Zero());
  if (firstMoments) firstMoments->assign(X.size(), Mat<D>::Zero());
  for (const auto& [key, f] : facets) {
    if (f.count != 1) continue;
    Vec<D> a = Vec<D>::Zero();
    if constexpr (D == 2) {
      const Vec<2> t = X[f.loop[1]] - X[f.loop[0]];
      a = Vec<2>(t.y(), -t.x());
    } else {
      for (std::size_t q = 0; q < f.loop.size(); ++q)
        a += 0.5 * X[f.loop[q]].cross(X[f.loop[(q + 1) % f.loop.size()]]);
    }
    for (Index node : f.loop)
      area[node] += a / double(f.loop.size());
    if (!firstMoments) continue;
    const std::size_t c = f.loop.size();
    for (std::size_t q = 0; q < c; ++q)
      for (std::size_t r = 0; r < c; ++r) {
        if (r == q) continue;
        const double w = c == 2             ? 1.0 / 6.0
                         : c == 3           ? 1.0 / 12.0
                         : (q + 2) % 4 == r ? 1.0 / 36.0
                                            : 1.0 / 18.0;
        (*firstMoments)[f.loop[q]] += w * (X[f.loop[r]] - X[f.loop[q]]) * a.transpose();
      }
  }
  return area;
}

}  // namespace tlsph
