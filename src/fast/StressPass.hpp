// F (6.69) as method/DeformationGradient.hpp, and the material's P, in one pass per particle;
// with the Taylor quadrature also grad grad u and P + P^q (TaylorQuadrature, as
// method/TaylorCorrection.hpp). In 3D the sums run padded, two particles at a time.
// Members of TlsphForces (TlsphForces.hpp).
#pragma once

#include <algorithm>
#include <type_traits>
#include <variant>
#include <vector>

#include "execution/MeetInTheMiddle.hpp"
#include "execution/Prefetch.hpp"
#include "fast/Padded.hpp"
#include "fast/SharedRows.hpp"
#include "fast/TaylorQuadrature.hpp"
#include "fast/TlsphForces.hpp"
#include "model/Types.hpp"

namespace tlsph {

// 3D: paddedU_ = u padded (the halo's as well), for the pair loops that gather it.
template <int D>
inline void TlsphForces<D>::padDisplacements(const std::vector<Vec<D>>& u) {
  if constexpr (D == 3) {
    const Index n = static_cast<Index>(paddedU_.size());
#pragma omp parallel for schedule(static)
    for (Index i = 0; i < n; ++i)
      paddedU_[i].template head<D>() = u[i];
  }
}

// F and P of every particle (F only for the passive ones), with the quadrature's second
// gradients in the same pass when Taylor.
template <int D>
template <bool Taylor>
inline void TlsphForces<D>::stressPass(const std::vector<Vec<D>>& u) {
  const auto& groups = comm_ ? ownedOfMaterial_ : particlesOfMaterial_;
  for (std::size_t m = 0; m < materials_.size(); ++m)
    std::visit(
        [&](const auto& model) {
          using Model = std::decay_t<decltype(model)>;
          if (D == 3 && !storesF())
            deformationAndStress<Model, Taylor, D == 3>(&model, groups[m], u);
          else
            deformationAndStress<Model, Taylor, false>(&model, groups[m], u);
        },
        materials_[m]);
  // Passive particles (mirrored ghosts): F for the penalty and the output, P stays zero.
  const auto& passive = comm_ ? ownedPassive_ : passive_;
  if (!passive.empty()) {
    if (D == 3 && !storesF())
      deformationAndStress<void, false, D == 3>(nullptr, passive, u);
    else
      deformationAndStress<void, false, false>(nullptr, passive, u);
    // their P + P^q is zero; where that is written into P + P^hg's array, clear the P^hg the
    // penalty added there last step
    if (quadrature_ && penaltyReadsF())
      for (Index i : passive)
        stress_[i].setZero();
  }
}

// F (and the penalty's own linear F where it has one) of the particles in group; their
// stress P unless Model is void (the passive particles); with Taylor, P + P^q as well.
// PaddedF: F summed padded and written only into the penalty's padded copy (!storesF(); a
// template argument: a branch on it in the loop made GCC spill around the log call).
template <int D>
template <class Model, bool Taylor, bool PaddedF>
inline void TlsphForces<D>::deformationAndStress(const Model* model,
                                                 const std::vector<Index>& group,
                                                 const std::vector<Vec<D>>& u) {
  const auto& nb = ref_.neighbours;
  const Index count = static_cast<Index>(group.size());
  [[maybe_unused]] TaylorQuadrature<D>* q = quadrature_.get();
  // P + P^q where the penalty adds P^hg in place, else its own array
  [[maybe_unused]] auto& taylorStress = penaltyReadsF() ? stress_ : quadratureStress_;
  constexpr Index kFitBatch = D == 3 && (Taylor || PaddedF) ? 2 : 1;
  // the fit's line ahead only where its rows stream (SharedRows::streams; a branch per pair
  // measured as slow as the prefetch itself)
  [[maybe_unused]] const bool aheadFit = Taylor && q->fitRows().streams();
  split_.reset(count);
#pragma omp parallel
  {
    MeetInTheMiddle::Chunks chunks(&split_, count);
    for (Index a, b; chunks.next(a, b);)
      for (Index p0 = a; p0 < b; p0 += kFitBatch) {
        // 3D: two particles' sums at once (TaylorQuadrature::paddedGradients, paddedGradU)
        [[maybe_unused]] typename TaylorQuadrature<D>::FitSum Ms[kFitBatch];  // [grad u | Gs]
        [[maybe_unused]] PaddedMat<D> gradUs[kFitBatch];  // 3D nodal: grad u padded
        if constexpr (Taylor && D == 3) {
          // two particles' sums, or the chunk's odd last one's
          auto sums = [&]<bool Ahead>(std::bool_constant<Ahead>) {
            if (p0 + 1 < b)
              q->template paddedGradients<Ahead>(group[p0], group[p0 + 1], paddedU_, Ms[0],
                                                 Ms[kFitBatch - 1]);
            else
              q->template paddedGradients<Ahead>(group[p0], paddedU_, Ms[0]);
          };
          aheadFit ? sums(std::true_type{}) : sums(std::false_type{});
        } else if constexpr (PaddedF) {
          if (p0 + 1 < b)
            paddedGradU(group[p0], group[p0 + 1], gradUs[0], gradUs[kFitBatch - 1]);
          else
            paddedGradU(group[p0], gradUs[0]);
        }
        for (Index p = p0; p < std::min(b, p0 + kFitBatch); ++p) {
          const Index i = group[p];
          // deformationGradientOf written out: the hot loop measured 2-3 % slower through the
          // call
          Mat<D> F;
          [[maybe_unused]] typename TaylorQuadrature<D>::SymMatrix Gs;  // 2D
          [[maybe_unused]] PaddedMat<D> Fp;                             // 3D: F padded
          if constexpr (Taylor && D == 3) {
            const auto& M = Ms[p - p0];
            Fp = padded<D, D>(Mat<D>::Identity()) + M.template leftCols<D>();  // (6.69)
            F = Fp.template topRows<D>();
          } else if constexpr (PaddedF && !Taylor) {
            const PaddedMat<D>& gradU = gradUs[p - p0];
            Fp = padded<D, D>(Mat<D>::Identity()) + gradU;  // (6.69)
            F = Fp.template topRows<D>();
          } else {
            Mat<D> gradU;
            if constexpr (Taylor) {
              q->gradients(i, u, gradU, Gs);  // grad u and grad grad u in one pass
            } else {
              const Vec<D> ui = u[i];
              gradU.setZero();
              const Vec<D>* g = correctedGradient_.row(i);
              const bool ahead = correctedGradient_.streams();
              for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++g) {
                if (ahead) prefetchAhead(g);
                gradU.noalias() += (u[nb.neighbour[k]] - ui) * g->transpose();
              }
            }
            F = Mat<D>::Identity() + gradU;  // (6.69)
          }
          if constexpr (PaddedF)
            paddedPenaltyF_[i] = Fp;
          else
            F_[i] = F;
          if constexpr (!std::is_void_v<Model>) {
            const Mat<D> P = firstPiolaKirchhoff<D>(*model, F);
            if constexpr (!Taylor) P_[i] = P;
            if constexpr (Taylor) {
              if constexpr (D == 3)
                q->paddedStressAt(i, Fp, Ms[p - p0], P, taylorStress[i]);
              else
                addTop<D>(q->stressAt(i, F, Gs), P, taylorStress[i]);  // P^q + P
            }
          }
        }
      }
  }
  if (separateHourglassGradient_) {
#pragma omp parallel for schedule(static)
    for (Index p = 0; p < count; ++p) {
      const Index i = group[p];
      hourglassF_[i] = deformationGradientOf(i, u, linearGradient_);
      if constexpr (D == 3)
        if (energyHourglass_) paddedPenaltyF_[i].template topRows<D>() = hourglassF_[i];
    }
  }
}

// F_I = 1 + sum_J (u_J - u_I) (x) g_IJ (6.69), for the gradient vectors g given.
template <int D>
inline Mat<D> TlsphForces<D>::deformationGradientOf(Index i, const std::vector<Vec<D>>& u,
                                                    const SharedRows<Vec<D>>& gradients) const {
  const auto& nb = ref_.neighbours;
  const Vec<D> ui = u[i];
  Mat<D> gradU = Mat<D>::Zero();
  const Vec<D>* g = gradients.row(i);
  const bool ahead = gradients.streams();  // SharedRows::streams
  for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++g) {
    if (ahead) prefetchAhead(g);
    gradU.noalias() += (u[nb.neighbour[k]] - ui) * g->transpose();
  }
  return Mat<D>::Identity() + gradU;
}

// Fills, once per compute() and when an observer first asks, what observers read but the
// step does not keep (fewer bytes written per step): F_ from the penalty's
// padded F (!storesF()) and, in 3D, the quadrature's grad grad u (recomputed from the padded
// u with the F pass's own sums). The step's values bit for bit. From serial code only.
template <int D>
inline void TlsphForces<D>::observe() const {
  if (observed_) return;
  observed_ = true;
  if constexpr (D == 3) {
    if (!storesF()) {
      const Index n = ref_.particleCount();
#pragma omp parallel for schedule(static)
      for (Index i = 0; i < n; ++i)
        F_[i] = paddedPenaltyF_[i].template topRows<D>();
    }
    if (quadrature_)
      for (const auto& group : comm_ ? ownedOfMaterial_ : particlesOfMaterial_) {
        const Index count = static_cast<Index>(group.size());
#pragma omp parallel for schedule(static)
        for (Index p = 0; p < count; ++p)
          quadrature_->keepSecondGradients(group[p], paddedU_);
      }
  }
}

}  // namespace tlsph
