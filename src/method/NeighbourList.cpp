#include "method/NeighbourList.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "model/Errors.hpp"

namespace tlsph {

namespace {

// Uniform cells at least one support radius wide: a particle's neighbours lie in the
// 3^D cells around its own.
template <int D>
struct CellGrid {
  Vec<D> origin;
  std::array<double, D> width{};
  std::array<Index, D> cells{};
  std::array<bool, D> periodic{};

  Index coordinate(const Vec<D>& x, int a) const {
    Index c = static_cast<Index>(std::floor((x[a] - origin[a]) / width[a]));
    if (periodic[a]) return (c % cells[a] + cells[a]) % cells[a];
    return std::clamp<Index>(c, 0, cells[a] - 1);
  }
  Index linear(const std::array<Index, D>& c) const {
    Index id = 0;
    for (int a = D - 1; a >= 0; --a)
      id = id * cells[a] + c[a];
    return id;
  }
  Index count() const {
    Index total = 1;
    for (int a = 0; a < D; ++a)
      total *= cells[a];
    return total;
  }
};

// For each query point, the points within supportRadius (sorted); `self`: the queries are the
// points, and a point is not its own neighbour; `rows` (with self): only those points are
// queried, list q belonging to point rows[q].
template <int D>
NeighbourList search(const std::vector<Vec<D>>& Q, const std::vector<Vec<D>>& X,
                     double supportRadius, const PeriodicBox<D>& box, bool self,
                     const std::vector<Index>* rows = nullptr) {
  const Index n = static_cast<Index>(X.size());
  const Index nq = static_cast<Index>(rows ? rows->size() : Q.size());
  NeighbourList list;
  list.offset.assign(nq + 1, 0);
  if (n == 0 || nq == 0) return list;

  Vec<D> lo = X[0], hi = X[0];
  for (const auto& x : X) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  CellGrid<D> grid;
  for (int a = 0; a < D; ++a) {
    grid.periodic[a] = box.periodic[a];
    if (box.periodic[a]) {
      if (!(box.length[a] >= 2.0 * supportRadius)) {
        std::ostringstream msg;
        msg << "periodic box length " << box.length[a] << " along axis " << a
            << " is shorter than twice the kernel support radius " << supportRadius
            << "; enlarge the periodic cell or reduce the support";
        throw SetupError(msg.str());
      }
      // The cells tile the period exactly so that the wrap-around is right.
      grid.origin[a] = box.origin[a];
      grid.cells[a] = std::max<Index>(1, static_cast<Index>(box.length[a] / supportRadius));
      grid.width[a] = box.length[a] / grid.cells[a];
    } else {
      grid.origin[a] = lo[a];
      grid.width[a] = supportRadius;
      grid.cells[a] = static_cast<Index>((hi[a] - lo[a]) / supportRadius) + 1;
    }
  }

  const Index cellCount = grid.count();
  std::vector<Index> cellStart(cellCount + 1, 0), cellParticles(n);
  std::vector<Index> cellOfParticle(n);
  std::vector<std::array<Index, D>> coordOfParticle(n);
  for (Index i = 0; i < n; ++i) {
    for (int a = 0; a < D; ++a)
      coordOfParticle[i][a] = grid.coordinate(X[i], a);
    cellOfParticle[i] = grid.linear(coordOfParticle[i]);
    ++cellStart[cellOfParticle[i] + 1];
  }
  for (Index c = 0; c < cellCount; ++c)
    cellStart[c + 1] += cellStart[c];
  {
    std::vector<Index> fill(cellStart.begin(), cellStart.end() - 1);
    for (Index i = 0; i < n; ++i)
      cellParticles[fill[cellOfParticle[i]]++] = i;
  }

  const double r2max = supportRadius * supportRadius;
  std::vector<std::vector<Index>> found(nq);
#pragma omp parallel for schedule(dynamic, 256)
  for (Index q = 0; q < nq; ++q) {
    const Index i = rows ? (*rows)[q] : q;  // the query point's index in Q
    std::array<Index, D> own;
    for (int a = 0; a < D; ++a)
      own[a] = self ? coordOfParticle[i][a] : grid.coordinate(Q[i], a);
    // Distinct neighbouring cell coordinates per axis (fewer than 3 cells: no repeats).
    std::array<std::array<Index, 3>, D> axisCells{};
    std::array<int, D> axisCount{};
    for (int a = 0; a < D; ++a) {
      int k = 0;
      for (int o = -1; o <= 1; ++o) {
        Index c = own[a] + o;
        if (grid.periodic[a]) {
          c = (c % grid.cells[a] + grid.cells[a]) % grid.cells[a];
        } else if (c < 0 || c >= grid.cells[a]) {
          continue;
        }
        bool seen = false;
        for (int m = 0; m < k; ++m)
          seen |= axisCells[a][m] == c;
        if (!seen) axisCells[a][k++] = c;
      }
      axisCount[a] = k;
    }
    std::array<int, D> it{};
    auto& out = found[q];
    while (true) {
      std::array<Index, D> c;
      for (int a = 0; a < D; ++a)
        c[a] = axisCells[a][it[a]];
      const Index cell = grid.linear(c);
      for (Index k = cellStart[cell]; k < cellStart[cell + 1]; ++k) {
        const Index j = cellParticles[k];
        if (self && j == i) continue;
        if (box.separation(Q[i], X[j]).squaredNorm() < r2max) out.push_back(j);
      }
      int a = 0;
      while (a < D && ++it[a] == axisCount[a])
        it[a++] = 0;
      if (a == D) break;
    }
    std::sort(out.begin(), out.end());
  }

  for (Index i = 0; i < nq; ++i)
    list.offset[i + 1] = list.offset[i] + static_cast<Index>(found[i].size());
  list.neighbour.resize(list.offset[nq]);
  for (Index i = 0; i < nq; ++i)
    std::copy(found[i].begin(), found[i].end(), list.neighbour.begin() + list.offset[i]);
  return list;
}

}  // namespace

template <int D>
NeighbourList buildNeighbourList(const std::vector<Vec<D>>& X, double supportRadius,
                                 const PeriodicBox<D>& box) {
  return search<D>(X, X, supportRadius, box, true);
}

template <int D>
NeighbourList buildNeighbourList(const std::vector<Vec<D>>& queries,
                                 const std::vector<Vec<D>>& points, double supportRadius,
                                 const PeriodicBox<D>& box) {
  return search<D>(queries, points, supportRadius, box, false);
}

template <int D>
NeighbourList buildNeighbourRows(const std::vector<Vec<D>>& X, const std::vector<Index>& rows,
                                 double supportRadius, const PeriodicBox<D>& box) {
  const NeighbourList found = search<D>(X, X, supportRadius, box, true, &rows);
  const Index n = static_cast<Index>(X.size());
  NeighbourList list;
  list.offset.assign(n + 1, 0);
  for (std::size_t q = 0; q < rows.size(); ++q)
    list.offset[rows[q] + 1] = found.count(static_cast<Index>(q));
  for (Index i = 0; i < n; ++i)
    list.offset[i + 1] += list.offset[i];
  list.neighbour.resize(found.neighbour.size());
  for (std::size_t q = 0; q < rows.size(); ++q) {
    const auto from = found.neighbour.begin() + found.offset[q];
    std::copy(from, from + found.count(static_cast<Index>(q)),
              list.neighbour.begin() + list.offset[rows[q]]);
  }
  return list;
}

template NeighbourList buildNeighbourList<2>(const std::vector<Vec<2>>&, double,
                                             const PeriodicBox<2>&);
template NeighbourList buildNeighbourList<3>(const std::vector<Vec<3>>&, double,
                                             const PeriodicBox<3>&);
template NeighbourList buildNeighbourList<2>(const std::vector<Vec<2>>&, const std::vector<Vec<2>>&,
                                             double, const PeriodicBox<2>&);
template NeighbourList buildNeighbourList<3>(const std::vector<Vec<3>>&, const std::vector<Vec<3>>&,
                                             double, const PeriodicBox<3>&);
template NeighbourList buildNeighbourRows<2>(const std::vector<Vec<2>>&, const std::vector<Index>&,
                                             double, const PeriodicBox<2>&);
template NeighbourList buildNeighbourRows<3>(const std::vector<Vec<3>>&, const std::vector<Index>&,
                                             double, const PeriodicBox<3>&);

}  // namespace tlsph
