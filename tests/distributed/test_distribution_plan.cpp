// The split of a distributed run (DistributionPlan.hpp), on two ranks played by two threads:
// every particle owned once, a mirrored ghost on the rank of the particles it follows, the
// halo exactly what the own particles read, the same summary on every rank; and the ranks
// agree on the stable step of the limiting particle.
#include <gtest/gtest.h>

#include <algorithm>
#include <barrier>
#include <cstring>
#include <random>
#include <thread>

#include "TestSupport.hpp"
#include "distributed/DistributionPlan.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

// Two ranks in one process: each collective is a meeting of both threads at a barrier, the
// reductions in rank order as MPI's.
class ThreadRanks {
 public:
  class Rank : public Communicator {
   public:
    Rank(ThreadRanks& shared, int rank) : shared_(shared), rank_(rank) {}
    int rank() const override { return rank_; }
    int size() const override { return 2; }
    void setPartition(const DomainPartition&, const NeighbourList&) override {}
    void exchangeHaloBytes(char*, std::size_t) override {}
    void gatherAllBytes(char*, std::size_t) override {}
    void sum(double* values, int count) override {
      reduce(values, count, [](double a, double b) { return a + b; });
    }
    void max(double* values, int count) override {
      reduce(values, count, [](double a, double b) { return std::max(a, b); });
    }
    void broadcastBytes(char* data, std::size_t bytes, int root) override {
      if (rank_ == root) shared_.bytes.assign(data, data + bytes);
      shared_.meet.arrive_and_wait();
      if (rank_ != root) std::memcpy(data, shared_.bytes.data(), bytes);
      shared_.meet.arrive_and_wait();
    }
    void barrier() override { shared_.meet.arrive_and_wait(); }

   private:
    template <class Op>
    void reduce(double* values, int count, Op op) {
      shared_.values[rank_].assign(values, values + count);
      shared_.meet.arrive_and_wait();
      for (int k = 0; k < count; ++k)
        values[k] = op(shared_.values[0][k], shared_.values[1][k]);
      shared_.meet.arrive_and_wait();
    }
    ThreadRanks& shared_;
    int rank_;
  };

  // Runs `body(rank)` on both ranks at once.
  template <class Body>
  void run(Body body) {
    Rank zero(*this, 0), one(*this, 1);
    std::thread other([&] { body(one); });
    body(zero);
    other.join();
  }

 private:
  std::barrier<> meet{2};
  std::array<std::vector<double>, 2> values;
  std::vector<char> bytes;
};

// A 2D block of 16 x 6 particles with a column of mirrored ghosts at x < 0 (odd reflection).
Scene<2> blockWithGhosts() {
  const double dx = 0.01;
  auto scene = sceneOf<2>(cellCentredLattice<2>(Vec<2>::Zero(), {16, 6}, dx), dx, 2.5,
                          testMaterial("neo-hookean"));
  const Index body = scene.particles.size();
  for (Index mirror = 0; mirror < body; ++mirror) {
    const Vec<2> X = scene.particles.referencePosition[mirror];
    if (X.x() > dx) continue;  // the first column
    MirrorGhost m;
    m.mirror = mirror;
    m.ghost = scene.particles.add(Vec<2>(-X.x(), X.y()), dx * dx, 0.1, 0, Motion::Mirrored);
    scene.mirrorGhosts.push_back(m);
  }
  return scene;
}

}  // namespace

TEST(DistributionPlan, ASerialRunHasNoPlan) {
  const Scene<2> scene = blockWithGhosts();
  EXPECT_FALSE(planDistribution(scene, nullptr, 0.025).active);
}

TEST(DistributionPlan, TwoRanksShareTheParticlesAndReadExactlyTheirHalo) {
  const Scene<2> scene = blockWithGhosts();
  const double H = scene.supportRadius;
  const Index n = scene.particles.size();
  const NeighbourList all =
      buildNeighbourList<2>(scene.particles.referencePosition, H, scene.periodicBox);
  std::array<DistributionPlan, 2> plans;
  ThreadRanks ranks;
  ranks.run([&](Communicator& comm) { plans[comm.rank()] = planDistribution(scene, &comm, H); });
  for (int r = 0; r < 2; ++r) {
    const auto& plan = plans[r];
    ASSERT_TRUE(plan.active);
    EXPECT_EQ(plan.partition.part, plans[0].partition.part);
    EXPECT_EQ(plan.partition.owned, plans[0].partition.owned);
    EXPECT_EQ(plan.summary.ranks, 2);
    EXPECT_EQ(plan.summary.method, plans[0].summary.method);
    EXPECT_EQ(plan.summary.halo, plans[0].summary.halo);
    const NeighbourStats whole = neighbourStatsOf(all);
    EXPECT_EQ(plan.neighbours.min, whole.min);
    EXPECT_EQ(plan.neighbours.max, whole.max);
    EXPECT_EQ(plan.neighbours.mean, whole.mean);
    // The halo: every neighbour of an own particle that another rank owns, nothing else.
    const auto& own = plan.partition.owned[r];
    EXPECT_FALSE(own.empty());
    std::vector<Index> halo;
    for (Index i : own)
      for (Index k = all.offset[i]; k < all.offset[i + 1]; ++k)
        if (plan.partition.part[all.neighbour[k]] != r) halo.push_back(all.neighbour[k]);
    std::sort(halo.begin(), halo.end());
    halo.erase(std::unique(halo.begin(), halo.end()), halo.end());
    EXPECT_EQ(plan.partition.halo[r], halo);
    std::vector<Index> rows = own;
    rows.insert(rows.end(), halo.begin(), halo.end());
    std::sort(rows.begin(), rows.end());
    EXPECT_EQ(plan.rows, rows);
    const auto mine = plan.ownedMask(r, n);
    for (Index i = 0; i < n; ++i)
      EXPECT_EQ(mine[i] == 1, plan.partition.part[i] == r) << i;
  }
  // Every particle owned once; each ghost on its mirror particle's rank.
  EXPECT_EQ(plans[0].partition.owned[0].size() + plans[0].partition.owned[1].size(),
            std::size_t(n));
  EXPECT_EQ(plans[0].summary.halo,
            Index(plans[0].partition.halo[0].size() + plans[1].partition.halo[1].size()));
  for (const auto& m : scene.mirrorGhosts)
    EXPECT_EQ(plans[0].partition.part[m.ghost], plans[0].partition.part[m.mirror]);
}

// The smaller step wins on every rank with the limiting particle's own numbers; between equal
// ratios, the lower particle index, as a serial run picks it.
TEST(DistributionPlan, RanksAgreeOnTheLimitingParticlesStep) {
  const StableStep zero{2e-5, 4, 0.01, 100.0, 10.0}, one{1e-5, 9, 0.005, 100.0, 10.0};
  std::array<StableStep, 2> agreed;
  ThreadRanks ranks;
  ranks.run([&](Communicator& comm) {
    agreed[comm.rank()] = globalStableStep(comm.rank() == 0 ? zero : one, comm);
  });
  for (const StableStep& s : agreed) {
    EXPECT_EQ(s.dt, one.dt);
    EXPECT_EQ(s.particle, one.particle);
    EXPECT_EQ(s.dx, one.dx);
    EXPECT_EQ(s.waveSpeed, one.waveSpeed);
    EXPECT_EQ(s.hourglassSpeed, one.hourglassSpeed);
  }
  const StableStep tie{3e-5, 2, 0.005, 100.0, 10.0};  // the ratio of `one`, a lower index
  ThreadRanks again;
  again.run([&](Communicator& comm) {
    agreed[comm.rank()] = globalStableStep(comm.rank() == 0 ? one : tie, comm);
  });
  for (const StableStep& s : agreed) {
    EXPECT_EQ(s.particle, 2);
    EXPECT_EQ(s.dt, tie.dt);
  }
}
