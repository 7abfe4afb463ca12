// The OpenMP team as the passes see it, with the serial answers in a build without OpenMP
// (-DTLSPH_OPENMP=OFF), so that callers need no #ifdef of their own.
#pragma once

#ifdef _OPENMP
#include <omp.h>
#endif

namespace tlsph {

// The threads the next parallel region will have (1 without OpenMP).
inline int maxThreads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

// Inside a parallel region: this thread's number and the team's size (0 of 1 without OpenMP).
// Plain members, not a structured binding: Clang 14 cannot capture those in a lambda.
struct ThreadSlot {
  int thread, threads;
};
inline ThreadSlot threadSlot() {
#ifdef _OPENMP
  return {omp_get_thread_num(), omp_get_num_threads()};
#else
  return {0, 1};
#endif
}

}  // namespace tlsph
