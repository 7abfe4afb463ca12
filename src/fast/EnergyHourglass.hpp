// E_hg and its gradient, as method/HourglassEnergy.hpp, in one pass over the pairs (shared
// rows, padded in 3D): the hourglass penalty as an energy (docs/method.md section 2; the
// conservative form of Ganzenmueller's (6.80)-(6.81)):
//   E_hg = 1/4 sum_I sum_J k_IJ |e_IJ|^2,   e_IJ = x_IJ - 1/2 (F_I + F_J) X_IJ,   k_IJ = V_I c_IJ.
// Its exact gradient has two parts: the spring  -sum_J k_IJ e_IJ  on I, and, through F, an
// "hourglass stress"  P^hg_I = -1/2 sum_J c_IJ e_IJ (x) X_IJ  that the internal-force pass sends
// through the same gradient vectors as P (dE = sum_I V_I P^hg_I : dF_I for the F-part).
// Conservative, objective (e -> R e under x -> R x) and zero for every affine field; with
// an F exact for quadratic fields it is zero for quadratic fields too.
#pragma once

#include <span>
#include <utility>
#include <vector>

#include "distributed/ReproducibleSum.hpp"
#include "execution/MeetInTheMiddle.hpp"
#include "execution/Prefetch.hpp"
#include "fast/Padded.hpp"
#include "fast/SharedRows.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D>
class EnergyHourglass {
 public:
  EnergyHourglass(const ReferenceConfiguration<D>& ref, PairArray<double> pairCoefficient,
                  const std::vector<double>& volume)
      : ref_(ref),
        volume_(volume),
        spring_(ref.particleCount(), Vec<D>::Zero()),
        sumCX_(ref.particleCount(), Vec<D>::Zero()),
        sumCXX_(ref.particleCount(), Mat<D>::Zero()) {
    const auto& nb = ref.neighbours;
    const PairArray<double>& c = pairCoefficient;
    for (Index i = 0; i < ref.particleCount(); ++i)
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
        sumCX_[i] += c[k] * ref.separation[k];
        sumCXX_[i] += c[k] * ref.separation[k] * ref.separation[k].transpose();
      }
    // The pass streams only the distinct rows (SharedRows.hpp), X_IJ padded (Padded.hpp).
    c_ = SharedRows<double>(nb, std::move(pairCoefficient));
    PairArray<PaddedVec<D>> separation(ref.separation.size());
    for (std::size_t k = 0; k < separation.size(); ++k)
      separation[k] = padded<D, 1>(ref.separation[k]);
    separation_ = SharedRows<PaddedVec<D>>(nb, std::move(separation));
  }

  // One pass over the pairs: stress[i] = P[i] + P^hg_i (what the force pass uses; P^hg_i
  // alone when P is null) and the spring force on every particle. F is the gradient the
  // penalty compares with; P^hg must go through that F's gradient vectors.
  // With H = F - 1, e_IJ = (u_I - u_J) - 1/2 H_I X_IJ - 1/2 H_J X_IJ; the H_I part is summed
  // once per particle through the constant moments sum_J c_IJ X_IJ and sum_J c_IJ X_IJ X_IJ^T.
  // With Gradient = true, F holds the displacement gradients H = F - 1 themselves (the
  // tangent's linearised pass, where 1 + dH would round dH off).
  // u, F, P and stress are plain (Vec<D>, Mat<D>) or padded (Padded.hpp: the force pass's
  // arrays); the sums run in the width of u.
  // `particles`: only these (a distributed run's own), else all. Gather: prefetch the
  // neighbours' F ahead (Prefetch.hpp; when F is read from memory).
  template <bool Gradient = false, bool Gather = false, class U, class FM, class PM, class SM>
  void evaluate(std::span<const U> u, std::span<const FM> F, const PM* P, std::span<SM> stress,
                const std::vector<Index>* particles = nullptr, MeetInTheMiddle* split = nullptr) {
    // the rows' line ahead only where they stream (SharedRows::streams): a branch per pair
    // measured as slow as the prefetch itself, so two loops
    if (separation_.streams() || c_.streams())
      evaluateRows<Gradient, Gather, true>(u, F, P, stress, particles, split);
    else
      evaluateRows<Gradient, Gather, false>(u, F, P, stress, particles, split);
  }

  template <bool Gradient, bool Gather, bool Ahead, class U, class FM, class PM, class SM>
  void evaluateRows(std::span<const U> u, std::span<const FM> F, const PM* P, std::span<SM> stress,
                    const std::vector<Index>* particles, MeetInTheMiddle* split) {
    constexpr int R = U::RowsAtCompileTime;  // D, or 4 when padded
    using Row = Eigen::Matrix<double, R, 1>;
    using Moment = Eigen::Matrix<double, R, D>;
    const auto& nb = ref_.neighbours;
    const Index count = particles ? static_cast<Index>(particles->size()) : ref_.particleCount();
    const Index* list = particles ? particles->data() : nullptr;
    if (split) split->reset(count);
#pragma omp parallel
    {
      MeetInTheMiddle::Chunks chunks(split, count);
      for (Index a, b; chunks.next(a, b);)
        for (Index p = a; p < b; ++p) {
          const Index i = list ? list[p] : p;
          const Row ui = u[i];
          Row sum = Row::Zero();
          Moment moment = Moment::Zero();
          const PaddedVec<D>* X = separation_.row(i);
          const double* c = c_.row(i);
          for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++X, ++c) {
            const Index j = nb.neighbour[k];
            if constexpr (Ahead) {
              prefetchAhead(X);
              prefetchAhead(c);
            }
            if constexpr (Gather) prefetchGather(F.data(), j);
            const Vec<D> Xij = X->template head<D>();
            const Row HjX = Gradient ? Row(F[j] * Xij) : Row(F[j] * Xij - X->template head<R>());
            const Row w = *c * ((ui - u[j]) - 0.5 * HjX);
            sum += w;
            moment.noalias() += w * Xij.transpose();
          }
          const auto Fi = F[i].template topRows<D>();
          const Mat<D> Hi = Gradient ? Mat<D>(Fi) : Mat<D>(Fi - Mat<D>::Identity());
          Vec<D> sumD = sum.template head<D>();
          Mat<D> momentD = moment.template topRows<D>();
          sumD -= 0.5 * (Hi * sumCX_[i]);                // sum_J c_IJ e_IJ
          momentD.noalias() -= 0.5 * (Hi * sumCXX_[i]);  // sum_J c_IJ e_IJ (x) X_IJ
          // P + P^hg, written as expressions: a Mat = Mat copy here is an out-of-line call once
          // the unit holds enough of them, and that spills the loop's sums to memory
          if (P)
            stress[i].template topRows<D>().noalias() = P[i].template topRows<D>() - 0.5 * momentD;
          else
            stress[i].template topRows<D>().noalias() = -0.5 * momentD;
          spring_[i] = -volume_[i] * sumD;  // -sum_J k_IJ e_IJ
        }
    }
  }

  // The bytes of the per-pair rows the pass streams (X_IJ and c_IJ, each distinct row once).
  double storedPairBytes() const {
    return separation_.storedBytes() + c_.storedBytes();
  }

  // Spring part of the force on particle i from the last evaluate().
  const Vec<D>& springForce(Index i) const {
    return spring_[i];
  }

  // E_hg = 1/4 sum_I V_I sum_J c_IJ |e_IJ|^2 for the displacements u and gradients F
  // (a diagnostic pass, not part of the force). Distributed: each rank its particles', summed
  // over the ranks with the same bits as a serial sum (ReproducibleSum.hpp).
  double energy(const std::vector<Vec<D>>& u, std::span<const Mat<D>> F,
                const std::vector<Index>* particles = nullptr, Communicator* comm = nullptr) const {
    const auto& nb = ref_.neighbours;
    const Index count = particles ? static_cast<Index>(particles->size()) : ref_.particleCount();
    std::vector<double> terms(static_cast<std::size_t>(count));
#pragma omp parallel for schedule(static)
    for (Index p = 0; p < count; ++p) {
      const Index i = particles ? (*particles)[p] : p;
      double squares = 0.0;
      const PaddedVec<D>* X = separation_.row(i);
      const double* c = c_.row(i);
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++X, ++c) {
        const Index j = nb.neighbour[k];
        const Vec<D> Xij = X->template head<D>();
        const Vec<D> e = (u[i] - u[j]) - 0.5 * ((F[i] + F[j]) * Xij - 2.0 * Xij);
        squares += *c * e.squaredNorm();
      }
      terms[p] = 0.25 * volume_[i] * squares;
    }
    return reproducibleSum(terms, comm);
  }

 private:
  const ReferenceConfiguration<D>& ref_;
  SharedRows<double> c_;                 // c_IJ
  SharedRows<PaddedVec<D>> separation_;  // X_IJ
  const std::vector<double>& volume_;
  std::vector<Vec<D>> spring_;
  std::vector<Vec<D>> sumCX_;   // sum_J c_IJ X_IJ
  std::vector<Mat<D>> sumCXX_;  // sum_J c_IJ X_IJ X_IJ^T
};

}  // namespace tlsph
