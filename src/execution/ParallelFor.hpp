// A loop over the indices 0..n-1 split among the OpenMP threads in contiguous ranges of equal
// length, for the solver's per-particle loops: the static shares the pair passes' threads start
// from and meet near (MeetInTheMiddle.hpp). Each thread then mostly writes the particles whose
// cache lines its core already holds: on two threads a
// per-particle array written by one thread alone moved half its lines between the cores every
// step (docs/performance.md).
#pragma once

#include "model/Types.hpp"

namespace tlsph {

template <class Body>
void parallelFor(Index n, Body&& body) {
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < n; ++i)
    body(i);
}

}  // namespace tlsph
