// Sums over particles whose bits do not depend on the number of OpenMP threads: the index range
// is cut into fixed blocks, each block is summed in index order (by whichever thread takes it),
// and the blocks' sums are added in block order. (An OpenMP reduction adds the threads' parts in
// the order the threads finish, which with three or more threads changes the last bits from run
// to run.) The energy books, and the kinetic energy whose peak kinetic damping detects, are
// summed this way, so a run and its restart agree bit for bit on any thread count.
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "model/Types.hpp"

namespace tlsph {

// K sums at once: term(i, sums) adds index i's parts to sums[0..K-1] (and may do other work for
// i, which runs exactly once per index).
template <int K, class Term>
std::array<double, K> orderedSums(Index n, Term&& term) {
  constexpr Index kBlock = 256;
  const Index blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::array<double, K>> parts(static_cast<std::size_t>(blocks));
#pragma omp parallel for schedule(static)
  for (Index b = 0; b < blocks; ++b) {
    std::array<double, K> s{};
    const Index end = std::min(n, (b + 1) * kBlock);
    for (Index i = b * kBlock; i < end; ++i)
      term(i, s);
    parts[static_cast<std::size_t>(b)] = s;
  }
  std::array<double, K> total{};
  for (const auto& s : parts)
    for (int k = 0; k < K; ++k)
      total[k] += s[k];
  return total;
}

// One sum: term(i) is index i's part.
template <class Term>
double orderedSum(Index n, Term&& term) {
  return orderedSums<1>(n, [&](Index i, std::array<double, 1>& s) { s[0] += term(i); })[0];
}

}  // namespace tlsph
