// A sum whose bits depend only on the values summed, not on their order nor on how they are
// split among threads or ranks: a decision the trajectory depends on (kinetic damping's peak
// test) must come out the same on any number of ranks.
//
// Pre-rounding in three levels (after Rump, Ogita and Oishi's error-free extraction): with
// m = max |x_i| and n values, sigma = 2^k >= 2 n m; q_i = (sigma + x_i) - sigma is exact and a
// multiple of 2^(k-53), so sum_i q_i is exact in any order; the remainders x_i - q_i (exact,
// at most 2^(k-53) in size) go through the same at a level 2^-52 finer, and so on. The result,
// S_1 + (S_2 + S_3), is as accurate as a sum in order (3 x (52 - log2 2n) bits below m) and the
// same wherever the terms were added.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "distributed/Communicator.hpp"

namespace tlsph {

// The sum of `values` over every rank (this rank's share given); comm null: a serial run.
inline double reproducibleSum(const std::vector<double>& values, Communicator* comm = nullptr) {
  double bound[2] = {0.0, static_cast<double>(values.size())};  // max |x|, and the count
  bool finite = true;
  for (double x : values) {
    finite = finite && std::isfinite(x);
    bound[0] = std::max(bound[0], std::abs(x));
  }
  if (comm) {
    finite = !comm->any(!finite);
    comm->max(&bound[0], 1);
    comm->sum(&bound[1], 1);
  }
  if (!finite || bound[0] == 0.0) {  // nothing to round: NaN or inf propagate, zero is zero
    std::array<double, 1> s{};
    for (double x : values)
      s[0] += x;
    if (comm) comm->sum(s.data(), 1);
    return s[0];
  }
  const double n = bound[1];
  // sigma_1 >= 2 n m, a power of two; each level is 2^-52 of the previous one's size.
  std::array<double, 3> sigma{};
  sigma[0] = std::ldexp(1.0, std::ilogb(bound[0]) + 2 + std::ilogb(n + 1.0) + 1);
  for (int l = 1; l < 3; ++l)
    sigma[l] = std::ldexp(sigma[l - 1], -52 + std::ilogb(n + 1.0) + 2);
  std::array<double, 3> s{};
  for (double x : values)
    for (int l = 0; l < 3; ++l) {
      const volatile double shifted = sigma[l] + x;  // volatile: no algebraic shortcut
      const double q = shifted - sigma[l];
      s[l] += q;
      x -= q;
    }
  if (comm) comm->sum(s.data(), 3);  // exact sums: any order gives the same bits
  return s[0] + (s[1] + s[2]);
}

}  // namespace tlsph
