// The order-independent sum (ReproducibleSum.hpp): the same bits for any order and
// any split of the values into parts (the ranks of a distributed run), accurate to a few ulps
// of the exact sum even under cancellation, and NaN / inf / zero passed through.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "distributed/ReproducibleSum.hpp"

using namespace tlsph;

namespace {

// A stand-in for the ranks: parts summed through a Communicator that adds the parts' sums in a
// given order (as MPI may) and takes maxima.
class PartsCommunicator final : public Communicator {
 public:
  explicit PartsCommunicator(int parts) : parts_(parts) {}
  int rank() const override { return 0; }
  int size() const override { return parts_; }
  void setPartition(const DomainPartition&, const NeighbourList&) override {}
  void exchangeHaloBytes(char*, std::size_t) override {}
  void gatherAllBytes(char*, std::size_t) override {}
  // Collected from every part before the combined result is handed back (see sumOverParts).
  void sum(double* values, int count) override {
    calls_.push_back(std::vector<double>(values, values + count));
    if (!result_.empty()) {
      std::copy(result_.front().begin(), result_.front().end(), values);
      result_.erase(result_.begin());
    }
  }
  void max(double* values, int count) override { sum(values, count); }
  void broadcastBytes(char*, std::size_t, int) override {}
  void barrier() override {}

  std::vector<std::vector<double>> calls_, result_;

 private:
  int parts_;
};

// reproducibleSum over values split into `parts` parts, as `parts` ranks would do it: each
// part's calls are recorded, combined across parts (sums added in reverse part order, maxima
// taken), and replayed.
double sumOverParts(const std::vector<double>& values, int parts) {
  std::vector<std::vector<double>> share(parts);
  for (std::size_t k = 0; k < values.size(); ++k)
    share[k % parts].push_back(values[k]);
  // First pass: record what each part contributes to each collective.
  std::vector<std::vector<std::vector<double>>> calls(parts);
  for (int r = 0; r < parts; ++r) {
    PartsCommunicator c(parts);
    reproducibleSum(share[r], &c);
    calls[r] = c.calls_;
  }
  // The combined collectives: call 0 any(non-finite) (max), 1 max |x|, 2 count (sum), 3 the
  // three level sums (sum), or for the plain path 3 the sum.
  std::vector<std::vector<double>> combined = calls[0];
  for (std::size_t call = 0; call < combined.size(); ++call)
    for (std::size_t v = 0; v < combined[call].size(); ++v) {
      const bool isMax = call <= 1;
      double total = isMax ? -std::numeric_limits<double>::infinity() : 0.0;
      for (int r = parts - 1; r >= 0; --r)
        total = isMax ? std::max(total, calls[r][call][v]) : total + calls[r][call][v];
      combined[call][v] = total;
    }
  PartsCommunicator c(parts);
  c.result_ = combined;
  return reproducibleSum(share[0], &c);
}

TEST(ReproducibleSum, SameBitsForAnyOrderAndAnySplit) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> values(10007);
  for (auto& v : values)  // positive, spread over 12 decades, as kinetic energies are
    v = std::pow(10.0, -12.0 * unit(rng)) * unit(rng);
  const double reference = reproducibleSum(values);
  for (int trial = 0; trial < 5; ++trial) {
    std::shuffle(values.begin(), values.end(), rng);
    EXPECT_EQ(reproducibleSum(values), reference);
    for (int parts : {2, 3, 4, 7})
      EXPECT_EQ(sumOverParts(values, parts), reference) << parts << " parts";
  }
  // Summed in order the bits do depend on the order (what the test guards against).
  double inOrder = 0.0, reversed = 0.0;
  for (double v : values)
    inOrder += v;
  for (auto it = values.rbegin(); it != values.rend(); ++it)
    reversed += *it;
  EXPECT_NE(inOrder, reversed);
}

TEST(ReproducibleSum, AccurateUnderCancellation) {
  // +x and -x pairs plus small terms: the exact sum is the small terms' sum, which a sum in order
  // loses against the large terms; the three levels keep it to a few ulps.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> values;
  long double exact = 0.0L;
  for (int k = 0; k < 2000; ++k) {
    const double big = 1e6 * unit(rng), small = 1e-9 * unit(rng);
    values.insert(values.end(), {big, -big, small});
    exact += static_cast<long double>(small);
  }
  std::shuffle(values.begin(), values.end(), rng);
  const double s = reproducibleSum(values);
  EXPECT_NEAR(s, static_cast<double>(exact), 1e-12 * static_cast<double>(exact));
}

TEST(ReproducibleSum, ZeroEmptyAndNonFinite) {
  EXPECT_EQ(reproducibleSum({}), 0.0);
  EXPECT_EQ(reproducibleSum({0.0, 0.0}), 0.0);
  EXPECT_EQ(reproducibleSum({1.5}), 1.5);
  EXPECT_EQ(reproducibleSum({-2.0, 0.5, 0.25}), -1.25);
  EXPECT_TRUE(std::isnan(reproducibleSum({1.0, std::nan(""), 2.0})));
  EXPECT_TRUE(std::isinf(reproducibleSum({1.0, std::numeric_limits<double>::infinity()})));
}

}  // namespace
