// No formula of method/: the memory traffic of one TlsphForces::compute(), counted from the
// arrays its passes touch, for the roofline (benchmarks/bench_cantilever.cpp,
// docs/performance.md), and the bytes the passes gather, which decide whether they prefetch.
// Members of TlsphForces (TlsphForces.hpp), kept next to the passes they describe.
#pragma once

#include <algorithm>

#include "fast/Padded.hpp"
#include "fast/TaylorQuadrature.hpp"
#include "fast/TlsphForces.hpp"
#include "model/Types.hpp"

namespace tlsph {

// Each per-pair stream read once per pass that reads it, as stored (each distinct row once,
// SharedRows.hpp; averaged per pair), each per-particle array read or written once per pass;
// neighbours' values (u_J, F_J, S_J, R_J) assumed to hit the cache, so this is the compulsory
// traffic. unsharedPerPair: the same streams stored whole.
template <int D>
struct TlsphForces<D>::Traffic {
  double perPair = 0.0;          // bytes per neighbour pair
  double perParticle = 0.0;      // bytes per particle
  double unsharedPerPair = 0.0;  // bytes per pair with every particle's rows stored
};

template <int D>
inline typename TlsphForces<D>::Traffic TlsphForces<D>::traffic() const {
  constexpr double I = sizeof(Index), V = sizeof(Vec<D>), M = sizeof(Mat<D>), d = sizeof(double);
  const TaylorQuadrature<D>* q = quadrature_.get();
  const bool taylor = q != nullptr;
  constexpr double S = sizeof(typename TaylorQuadrature<D>::Sym),
                   SM = sizeof(typename TaylorQuadrature<D>::SymMatrix),
                   PSM = sizeof(typename TaylorQuadrature<D>::PaddedSymMatrix);
  // padded (Padded.hpp): P + P^q, P + P^hg, and in 3D the penalty's u and F
  constexpr double PV = sizeof(PaddedVec<D>), PM = sizeof(PaddedMat<D>);
  const double paddedCopies = D == 3 && energyHourglass_ ? 1.0 : 0.0;
  const double pairs = std::max<double>(1.0, ref_.neighbours.pairCount());
  Traffic t;
  // each shared stream: its stored bytes once, and a row start per particle
  auto stream = [&](double storedBytes, double unsharedBytesPerPair) {
    t.perPair += storedBytes / pairs;
    t.unsharedPerPair += unsharedBytesPerPair;
    t.perParticle += I;
  };
  auto pairIndices = [&] {  // j, streamed whole
    t.perPair += I;
    t.unsharedPerPair += I;
  };
  // F pass: j and g_IJ (+ S_IJ); offset, group entry, u_I; writes F (unless only the padded
  // copy below), P (nodal) or P + P^q, the hyperstress and in 2D the second gradients (Taylor,
  // reading the particle's three constants).
  pairIndices();
  if (taylor)
    stream(q->fitRows().storedBytes(), V + S);
  else
    stream(correctedGradient_.storedBytes(), V);
  t.perParticle += 2 * I + V + (storesF() ? M : 0.0);
  t.perParticle += taylor ? PM + (D == 2 ? SM : 0.0) + PSM + 3 * d : M;
  t.perParticle += paddedCopies * PM;  // the padded F the penalty gathers
  if (separateHourglassGradient_) {    // the penalty's own F through g^lin_IJ
    pairIndices();
    stream(linearGradient_.storedBytes(), V);
    t.perParticle += I + V + M;
  }
  if (energyHourglass_) {  // j, X_IJ, c_IJ; u_I, F_I, P_I, moments, V_I; writes P + P^hg, spring
    pairIndices();
    stream(energyHourglass_->storedPairBytes(), PV + d);
    t.perParticle += paddedCopies * (V + PV);  // u padded
    t.perParticle += I;                        // the second row start
    const double P = separateHourglassGradient_ ? 0.0 : taylor ? PM : M;
    t.perParticle += I + PV + PM + P + M + V + V + PM + d;
  }
  // Force pass: j, t_IJ (+ T_IJ) (+ t^lin_IJ); S_I, G_I (+ R_I, Sum_I), V_I; writes f.
  // Summed from its sources: the records [t_IJ (+ T_IJ)] in the sources' rows, and each
  // target's sum written (its own terms) and read back (the sources' terms hit the cache).
  pairIndices();
  if (scattersInternalForce()) {
    stream(taylor ? taylorScatter_->storedPairBytes() : nodalScatter_->storedPairBytes(),
           V + (taylor ? S : 0.0));
    t.perParticle += 2 * PV;
  } else {
    stream(reverseGradient_.storedBytes(), V);
    if (taylor) stream(q->reverseRows().storedBytes(), S);
    if (separateHourglassGradient_) stream(linearReverse_.storedBytes(), V);
  }
  const bool paddedS = (energyHourglass_ && !separateHourglassGradient_) || taylor;
  t.perParticle += I + (paddedS ? PM : M) + V + (taylor ? PSM + S : 0.0) + d + V;
  if (ganzenmueller_ || viscosity_) t.perParticle += V;     // u_I for x_IJ
  if (separateHourglassGradient_) t.perParticle += PM + V;  // P^hg_I, G^lin_I
  if (energyHourglass_) t.perParticle += V;                 // the spring force
  // (the textbook form and the viscosity stream their per-pair arrays whole)
  auto whole = [&](double bytes) {
    t.perPair += bytes;
    t.unsharedPerPair += bytes;
  };
  if (ganzenmueller_) {  // X_IJ, c_IJ; F_I of the penalty; writes its force
    whole(V + d);
    t.perParticle += M + V;
  }
  if (viscosity_) {  // X_IJ (if not already), the pair's two coefficients; v_I; writes its force
    whole((ganzenmueller_ ? 0.0 : V) + 2 * d);
    t.perParticle += 2 * V;
  }
  return t;
}

// What the force pass (S_J, R_J; summed from its sources, the sums it adds to) and the
// penalty (F_J) gather, in bytes per particle.
template <int D>
inline double TlsphForces<D>::gatheredBytesPerParticle() const {
  const double force =
      scattersInternalForce()
          ? sizeof(PaddedVec<D>)
          : sizeof(PaddedMat<D>) +
                (quadrature_ ? sizeof(typename TaylorQuadrature<D>::PaddedSymMatrix) : 0);
  return force + (energyHourglass_ ? sizeof(PaddedMat<D>) : 0);
}

}  // namespace tlsph
