// E_q and its gradient, as method/TaylorCorrection.hpp, fused into TlsphForces' passes (shared
// rows, in 3D padded and two particles at a time): the second-order correction of the
// one-point nodal quadrature of the strain energy.
//
// E = sum_I V_I psi(F_I) is the midpoint rule on the particles' lattice cells: for a field
// whose energy density varies quadratically across a cell it misses
//   int_cell psi dV - V_I psi(F_I) = V_I l_I^2 / 24 sum_a d^2 psi / dX_a^2,   l_I = V_I^(1/d),
// and in bending (psi ~ z^2) that is exactly the fraction 1/n^2 of the bending energy with n
// particles through the thickness (the cell-centred layers' sum of z^2 is t^3/12 (1 - 1/n^2)):
// the discretisation is too soft by that much. This term adds the missing part,
//   E_q = sum_I V_I l_I^2 / 24 sum_a e_a : C0 : e_a,    e_a = sym(F_I^T dF_I/dX_a),
// with C0 the material's small-strain stiffness (lambda, mu) and dF/dX_a = the second
// derivatives of u from the same weighted least-squares quadratic fit that gives F
// (ReferenceConfiguration, quadratic correction): grad grad u_I = sum_J (u_J - u_I) (x) S_IJ.
// e_a is objective (F -> R F, dF -> R dF leave F^T dF unchanged) and zero for every affine
// displacement (rigid rotations included); E_q >= 0. For the linear-elastic material, whose
// energy is that of the small strain, e_a = sym(dF/dX_a) (F -> 1 below, and no P^q): the term
// is then quadratic in u like the rest of its energy.
// Gradient, with sigma_a = C0 : e_a and c_I = l_I^2 / 12:
//   through F:           P^q_I = c_I sum_a G_a sigma_a      (added to P, same vectors g_IJ)
//   through G_a = dF/dX_a: R_Ia = c_I F_I sigma_a,  f_I += V_I (R_I . Sum_I - sum_J R_J . T_IJ)
// with (R . S) = sum_ab R_a(:, b) S(b, a), Sum_I = sum_J S_IJ and T_IJ = (V_J / V_I) S_JI
// (S_IJ symmetric: stored as its D(D+1)/2 entries, R likewise, see symmetric()).
// With the moments of each particle's weight (model/QuadratureMoments.hpp: the nodes of a
// meshed body), the term is the general one of method/TaylorCorrection.hpp,
//   E_q = sum_I V_I [1/2 sum_ab N_ab e_a : C0 : e_b + sum_a mu_a (C0 : E) : e_a],
// evaluated unfused per particle (generalStress); lattice scenes, mu = 0 and N = c_I 1, run the
// fused code above, one branch per particle on a flag of the scene.
// Only with the quadratic correction; particles on the linear fallback and passive particles
// (mirrored ghosts) carry no correction.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "distributed/Communicator.hpp"
#include "execution/OrderedSum.hpp"
#include "execution/Prefetch.hpp"
#include "fast/Padded.hpp"
#include "fast/SharedRows.hpp"
#include "materials/Material.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "method/TaylorCorrection.hpp"
#include "model/QuadratureMoments.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D>
class TaylorQuadrature {
 public:
  using Gradients = std::array<Mat<D>, D>;  // G_a = dF/dX_a, a = 0..D-1
  // Symmetric pairs (a, b), a <= b, in the fit's order: a second-derivative vector S_IJ and a
  // hyperstress are stored by these, D (D + 1) / 2 entries (half the flops and the memory).
  static constexpr int P = D * (D + 1) / 2;
  using Sym = Eigen::Matrix<double, P, 1>;
  using SymMatrix = Eigen::Matrix<double, D, P>;
  using PaddedSymMatrix = PaddedMat<D, P>;  // R_I as the force pass gathers it (Padded.hpp)
  // A pair's whole fit, [g_IJ, S_IJ]: the gradient vector and the second-derivative vector in
  // one record, so that the F pass reads one stream and multiplies it as one row (gradients()).
  using Fit = Eigen::Matrix<double, 1, D + P>;

  // Builds the second-derivative vectors S_IJ from the quadratic fit (TaylorQuadrature.cpp);
  // moments: the particles' quadrature moments (empty: lattice cells).
  TaylorQuadrature(const ReferenceConfiguration<D>& ref, const std::vector<Material>& materials,
                   const std::vector<std::uint16_t>& materialOf, const std::vector<double>& volume,
                   const std::vector<std::uint8_t>& passive,
                   const QuadratureMoments<D>& moments = {});

  // grad grad u at particle i: G_a(:, b) = d^2 u / dX_a dX_b.
  Gradients secondGradients(Index i, const std::vector<Vec<D>>& u) const {
    const auto& nb = ref_.neighbours;
    SymMatrix Gs = SymMatrix::Zero();
    const Vec<D> ui = u[i];
    const Fit* fit = fit_.row(i);
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++fit)
      Gs.noalias() += (u[nb.neighbour[k]] - ui) * fit->template tail<P>();
    return unpack(Gs);
  }

  // G_a(:, b) = G_b(:, a) = column (a, b) of the symmetric storage.
  static Gradients unpack(const SymMatrix& Gs) {
    Gradients G;
    int t = 0;
    for (int a = 0; a < D; ++a)
      for (int b = a; b < D; ++b, ++t) {
        G[a].col(b) = Gs.col(t);
        G[b].col(a) = Gs.col(t);
      }
    return G;
  }

  // The force pass's parts, fused into TlsphForces' loops (one pass over the pairs each):
  // in the F loop, grad u and Gs = grad grad u together (gradients), then stressAt(i, F_I, Gs)
  // = P^q_I, added to the stress sent through g_IJ, which also keeps the hyperstress R_I (and
  // in 2D G_I); in the force loop, f_I += V_I (R_I . Sum_I - sum_J R_J . T_IJ) (hyperForce*).
  //
  // [grad u | Gs] = sum_J (u_J - u_I) (x) [g_IJ, S_IJ] (6.69 and the fit's second
  // derivatives): row a accumulates du_a [g_IJ, S_IJ], one (D + P)-wide multiply-add per row
  // and pair, which vectorises across the row (8-11 % faster per step in 3D than the
  // separate D x D and D x P products). 2D; 3D: paddedGradients.
  void gradients(Index i, const std::vector<Vec<D>>& u, Mat<D>& gradU, SymMatrix& Gs) const {
    const auto& nb = ref_.neighbours;
    std::array<Fit, D> rows;
    for (auto& row : rows)
      row.setZero();
    const Vec<D> ui = u[i];
    const Fit* fit = fit_.row(i);
    const bool ahead = fit_.streams();
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++fit) {
      if (ahead) prefetchAhead(fit);
      const Vec<D> du = u[nb.neighbour[k]] - ui;
      const Fit& c = *fit;
      for (int a = 0; a < D; ++a)
        rows[a].noalias() += du[a] * c;
    }
    for (int a = 0; a < D; ++a) {
      gradU.row(a) = rows[a].template head<D>();
      Gs.row(a) = rows[a].template tail<P>();
    }
  }
  // P^q_I, keeping G_I and the hyperstress R_I (2D; 3D: paddedStressAt, which keeps R_I).
  Mat<D> stressAt(Index i, const Mat<D>& F, const SymMatrix& Gs) requires(D == 2) {
    if (weight_[i] == 0.0) return Mat<D>::Zero();  // R_i stays zero
    G_[i] = Gs;
    if (general_) [[unlikely]]
      return generalStress(i, F, Gs);
    if (smallStrain_[i]) return smallStrainHyperstress(i, Gs).template topRows<D>();
    const Gradients A = unpack(F.transpose() * Gs);  // F^T G_a
    const Gradients G = unpack(Gs);
    Gradients sigma;
    Mat<D> Pq = Mat<D>::Zero();
    for (int a = 0; a < D; ++a) {
      sigma[a] = weight_[i] * stressOf(i, A[a]);
      Pq.noalias() += G[a] * sigma[a];
    }
    // R_a = F sigma_a (symmetric). In 2D the D top rows are all the padded rows; naming them
    // (here and above) keeps the body well-formed for D = 3, which Clang 14 instantiates
    // against the constraint through the explicit instantiation in TaylorQuadrature.cpp.
    R_[i].template topRows<D>().noalias() = F * symmetric(sigma);
    return Pq;
  }

  // Distributed runs: the halo's hyperstresses (read by the force pass), and every rank's
  // second gradients (read by the energy and the probes).
  void exchangeHalo(Communicator& comm) { comm.exchangeHalo(R_); }
  void gatherAll(Communicator& comm) { comm.gatherAll(G_); }

  PaddedVec<D> hyperForceOwn(Index i) const { return R_[i] * sum_[i]; }
  // Every particle's hyperstress R_I (symmetric storage, padded), as the force pass reads it.
  const LargeArray<PaddedSymMatrix>& hyperstresses() const { return R_; }
  // Particle i's row of T_IJ (T[m] for its m-th pair), and one pair's term R_J . T_IJ;
  // ahead: prefetch T's line ahead (the caller's reverseRows().streams(), read once per pass).
  const Sym* reverseRow(Index i) const { return reverse_.row(i); }
  template <bool Gather = false>
  PaddedVec<D> hyperForcePair(const Sym* T, Index j, bool ahead) const {
    if (ahead) prefetchAhead(T);
    if constexpr (Gather) prefetchGather(R_.data(), j);
    return R_[j] * *T;
  }

  // Linearised (method/TaylorCorrection::linearised): dstress[i] += dP^q_i and the linearised
  // hyperstress force, for the direction v (with dH its displacement gradient) about the state
  // (F, G) of a force pass.
  void linearise(const std::vector<Vec<D>>& v, const std::vector<Mat<D>>& dH,
                 std::span<const Mat<D>> F, const std::vector<SymMatrix>& Gs,
                 std::vector<Mat<D>>& dstress) {
    const Index n = ref_.particleCount();
#pragma omp parallel for schedule(static)
    for (Index i = 0; i < n; ++i) {
      if (weight_[i] == 0.0) {
        R_[i].setZero();
        continue;
      }
      const Gradients dG = secondGradients(i, v);
      const Gradients G = unpack(Gs[i]);
      if (general_) {
        const auto d = generalLinearised(i, F[i], G, dH[i], dG);
        R_[i].template topRows<D>() = symmetric(d.hyperstress);
        dstress[i] += d.stress;
        continue;
      }
      // small strain: F -> 1, dH -> 0, and no P^q
      const bool small = smallStrain_[i];
      const Mat<D> Fi = small ? Mat<D>::Identity() : F[i];
      const Mat<D> dHi = small ? Mat<D>::Zero() : dH[i];
      Mat<D> dPq = Mat<D>::Zero();
      Gradients R;
      for (int a = 0; a < D; ++a) {
        const Mat<D> sigma = weight_[i] * stressOf(i, Fi.transpose() * G[a]);
        const Mat<D> dsigma =
            weight_[i] * stressOf(i, dHi.transpose() * G[a] + Fi.transpose() * dG[a]);
        if (!small) dPq.noalias() += dG[a] * sigma + G[a] * dsigma;
        R[a] = dHi * sigma + Fi * dsigma;
      }
      R_[i].template topRows<D>() = symmetric(R);
      dstress[i] += dPq;
    }
    hyperForce(R_);
  }

  // The linearised hyperstress force on particle i from the last linearise().
  const Vec<D>& force(Index i) const {
    return force_[i];
  }
  // grad grad u of every particle at the last force pass, in the symmetric storage (unpack()).
  // In 3D the pass does not keep it: TlsphForces fills it (keepSecondGradients) before an
  // observer reads it, through TlsphForces::quadrature().
  const std::vector<SymMatrix>& secondGradients() const {
    return G_;
  }
  // 3D: G_i from u as the F pass computed it (paddedGradients: the same sums, the same bits);
  // zero where the pass computes no correction.
  void keepSecondGradients(Index i, std::span<const PaddedVec<D>> u) requires(D == 3) {
    if (weight_[i] != 0.0) {
      FitSum M;
      paddedGradients(i, u, M);
      G_[i] = M.template rightCols<P>().template topRows<D>();
    }
  }

  // The stored per-pair rows (SharedRows.hpp): the fit [g_IJ, S_IJ] and T_IJ.
  const SharedRows<Fit>& fitRows() const {
    return fit_;
  }
  const SharedRows<Sym>& reverseRows() const {
    return reverse_;
  }

  // E_q at the state of the last force pass.
  double energy(std::span<const Mat<D>> F) const {
    return orderedSum(ref_.particleCount(), [&](Index i) {
      if (weight_[i] == 0.0) return 0.0;
      if (general_) return generalEnergy(i, F[i], unpack(G_[i]));
      double e = 0.0;
      const Gradients G = unpack(G_[i]);
      for (int a = 0; a < D; ++a) {
        const Mat<D> ea = smallStrain_[i] ? G[a] : Mat<D>(F[i].transpose() * G[a]);
        e += (stressOf(i, ea).array() * (0.5 * (ea + ea.transpose())).array()).sum();
      }
      return 0.5 * volume_[i] * weight_[i] * e;  // V l^2 / 24 sum_a e_a : C0 : e_a
    });
  }

  // The pair loops written with #pragma GCC unroll come last: clang-format 14 loses the class
  // scope after them and would split the short functions above.
  // In 3D the same sums on padded columns (Padded.hpp): M = [grad u | Gs], column m
  // accumulating (u_J - u_I) times entry m of [g_IJ, S_IJ], one 4-wide multiply-add per column
  // and pair with u gathered as one 256-bit word (the rows above split into 2-wide and scalar
  // ones); F, grad grad u and P^q come out padded for paddedStressAt.
  using FitSum = PaddedMat<D, D + P>;
  // Written into out from a local (returned by value, the 288-byte result was zeroed with a
  // memset call and copied with a memcpy call per particle).
  // Ahead: prefetch the fit's line ahead (only where its rows stream, SharedRows::streams).
  template <bool Ahead = true>
  void paddedGradients(Index i, std::span<const PaddedVec<D>> u, FitSum& out) const {
    const auto& nb = ref_.neighbours;
    FitSum M = FitSum::Zero();  // a local: GCC keeps it in registers through the loop
    const PaddedVec<D> ui = u[i];
    const Fit* fit = fit_.row(i);
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++fit) {
      if constexpr (Ahead) prefetchAhead(fit);
      const PaddedVec<D> du = u[nb.neighbour[k]] - ui;
      const Fit& c = *fit;
#pragma GCC unroll 9
      for (int m = 0; m < D + P; ++m)
        M.col(m).noalias() += du * c[m];
    }
    out = M;
  }

  // Two particles' sums at once, each entry the same multiply-adds in the same order as
  // paddedGradients (the same bits). One particle's sums are nine dependent chains of 4-cycle
  // multiply-adds; held as three 8-wide rows (du_a [g_IJ, S_IJ] without its last entry) and one
  // padded column (du S_IJ's last entry), two particles' eight chains keep both 512-bit FMA
  // pipes busy. Without AVX-512: paddedGradients twice.
  template <bool Ahead = true>
  void paddedGradients(Index i0, Index i1, std::span<const PaddedVec<D>> u, FitSum& out0,
                       FitSum& out1) const {
#if defined(__AVX512F__)
    if constexpr (D == 3) {
      const auto& nb = ref_.neighbours;
      const Index* j = nb.neighbour.data();
      Sums s0(u[i0]), s1(u[i1]);
      const double* fit0 = fit_.row(i0)->data();
      const double* fit1 = fit_.row(i1)->data();
      Index k0 = nb.offset[i0], k1 = nb.offset[i1];
      const Index end0 = nb.offset[i0 + 1], end1 = nb.offset[i1 + 1];
      for (const Index both = k0 + std::min(end0 - k0, end1 - k1); k0 < both;
           ++k0, ++k1, fit0 += D + P, fit1 += D + P) {
        if constexpr (Ahead) {
          prefetchAhead(fit0);
          prefetchAhead(fit1);
        }
        s0.add(u[j[k0]], fit0);
        s1.add(u[j[k1]], fit1);
      }
      for (; k0 < end0; ++k0, fit0 += D + P) {
        if constexpr (Ahead) prefetchAhead(fit0);
        s0.add(u[j[k0]], fit0);
      }
      for (; k1 < end1; ++k1, fit1 += D + P) {
        if constexpr (Ahead) prefetchAhead(fit1);
        s1.add(u[j[k1]], fit1);
      }
      s0.store(out0);
      s1.store(out1);
      return;
    }
#endif
    paddedGradients<Ahead>(i0, u, out0);
    paddedGradients<Ahead>(i1, u, out1);
  }

  // stress = Pm + P^q_I padded (Pm the material's P), keeping R_I, from F and paddedGradients'
  // M (3D). A column of F^T G_a, of G_a sigma_a and of F [sigma] is one 4-wide multiply-add per
  // term; the scalar work is only sigma_a = w C0 : sym(A_a) from the entries of A. Pm is added
  // here, each column in a register, and the sum stored straight into the caller's array:
  // returned by value, GCC wrote P^q in 16-byte halves that the caller reloaded as 256-bit
  // words (a store-to-load forwarding stall per column).
  void paddedStressAt(Index i, const PaddedMat<D>& F, const FitSum& M, const Mat<D>& Pm,
                      PaddedMat<D>& stress) {
    PaddedMat<D> Pq = PaddedMat<D>::Zero();  // P^q: zero where there is no correction
    if (weight_[i] == 0.0) {                 // (R_i stays zero)
      addTop<D>(Pq, Pm, stress);
      return;
    }
    const auto Gp = M.template rightCols<P>();  // Gs padded
    const auto Gs = Gp.template topRows<D>();
    if (general_) [[unlikely]] {
      addTop<D>(padded<D, D>(generalStress(i, F.template topRows<D>(), Gs)), Pm, stress);
      return;
    }
    if (smallStrain_[i]) {
      smallStrainHyperstress(i, Gs);
      addTop<D>(Pq, Pm, stress);
      return;
    }
    PaddedMat<D, P> A;  // column (a, b) = F^T G_a(:, b) = A_a(:, b)
    A.noalias() = transposed<D>(F).lazyProduct(Gs);
    const double lambda = weight_[i] * lambda_[i], mu = weight_[i] * mu_[i];
    Gradients sigma;  // sigma_a = lambda tr(A_a) 1 + mu (A_a + A_a^T)
#pragma GCC unroll 3
    for (int a = 0; a < D; ++a) {
      double trace = 0.0;
#pragma GCC unroll 3
      for (int b = 0; b < D; ++b)
        trace += A(b, sym(a, b));
#pragma GCC unroll 3
      for (int b = 0; b < D; ++b)
#pragma GCC unroll 3
        for (int c = b; c < D; ++c) {
          const double s =
              mu * (A(b, sym(a, c)) + A(c, sym(a, b))) + (b == c ? lambda * trace : 0.0);
          sigma[a](b, c) = s;
          sigma[a](c, b) = s;
        }
    }
    // P^q = sum_a G_a sigma_a, column c
#pragma GCC unroll 3
    for (int c = 0; c < D; ++c)
#pragma GCC unroll 3
      for (int a = 0; a < D; ++a)
#pragma GCC unroll 3
        for (int b = 0; b < D; ++b)
          Pq.col(c).noalias() += Gp.col(sym(a, b)) * sigma[a](b, c);
    R_[i].noalias() = F.lazyProduct(symmetric(sigma));  // R_a = F sigma_a
    addTop<D>(Pq, Pm, stress);
  }

 private:
#if defined(__AVX512F__)
  // One particle's [grad u | Gs] in the two-particle paddedGradients: rows a = 0..2 of its
  // first eight columns, each entry fma(du_a, c_m, sum) as there, and its last column padded.
  // (named members, no arrays: GCC kept arrays of them on the stack, stored every pair)
  struct Sums {
    __m512d row0, row1, row2;
    __m256d last;
    __m512d ui0, ui1, ui2;  // u_I's entries, broadcast
    __m256d ui;
    explicit Sums(const PaddedVec<D>& u) requires(D == 3)
        : row0(_mm512_setzero_pd()),
          row1(_mm512_setzero_pd()),
          row2(_mm512_setzero_pd()),
          last(_mm256_setzero_pd()),
          ui0(_mm512_set1_pd(u[0])),
          ui1(_mm512_set1_pd(u[1])),
          ui2(_mm512_set1_pd(u[2])),
          ui(_mm256_loadu_pd(u.data())) {}
    // one pair: u_J and the record [g_IJ, S_IJ] (nine doubles; the caller prefetches them: in
    // here GCC dropped the prefetch); du_a broadcast as u_J's entry from memory minus u_I's
    [[gnu::always_inline]] void add(const PaddedVec<D>& uj, const double* c) requires(D == 3) {
      // one load of the record's first eight entries, kept in a register: GCC otherwise folds
      // it into each of the three multiply-adds, three 64-byte loads of which, the records
      // being 72 B apart, most split across two cache lines (+6-10 % per step)
      __m512d first = _mm512_loadu_pd(c);
      __asm__("" : "+v"(first));
      row0 = _mm512_fmadd_pd(_mm512_sub_pd(_mm512_set1_pd(uj[0]), ui0), first, row0);
      row1 = _mm512_fmadd_pd(_mm512_sub_pd(_mm512_set1_pd(uj[1]), ui1), first, row1);
      row2 = _mm512_fmadd_pd(_mm512_sub_pd(_mm512_set1_pd(uj[2]), ui2), first, row2);
      last = _mm256_fmadd_pd(_mm256_sub_pd(_mm256_loadu_pd(uj.data()), ui),
                             _mm256_broadcast_sd(c + 8), last);
    }
    // the low (h = 0) or high four entries (the masked extract: GCC 12 warns on the undefined
    // source of the plain one and of the cast)
    [[gnu::always_inline]] static __m256d half(__m512d r, int h) {
      return h ? _mm512_mask_extractf64x4_pd(_mm256_setzero_pd(), 0xf, r, 1)
               : _mm512_mask_extractf64x4_pd(_mm256_setzero_pd(), 0xf, r, 0);
    }
    // M's columns (padded, fourth row zero), transposed in registers (stored whole: the stress
    // reads them as 256-bit words)
    [[gnu::always_inline]] void store(FitSum& M) const requires(D == 3) {
      const __m256d zero = _mm256_setzero_pd();
      for (int h = 0; h < 2; ++h) {  // columns 4h .. 4h + 3
        const __m256d r0 = half(row0, h), r1 = half(row1, h), r2 = half(row2, h);
        const __m256d t0 = _mm256_unpacklo_pd(r0, r1);    // r00 r10 | r02 r12
        const __m256d t1 = _mm256_unpackhi_pd(r0, r1);    // r01 r11 | r03 r13
        const __m256d t2 = _mm256_unpacklo_pd(r2, zero);  // r20 0 | r22 0
        const __m256d t3 = _mm256_unpackhi_pd(r2, zero);  // r21 0 | r23 0
        _mm256_storeu_pd(M.col(4 * h).data(), _mm256_permute2f128_pd(t0, t2, 0x20));
        _mm256_storeu_pd(M.col(4 * h + 1).data(), _mm256_permute2f128_pd(t1, t3, 0x20));
        _mm256_storeu_pd(M.col(4 * h + 2).data(), _mm256_permute2f128_pd(t0, t2, 0x31));
        _mm256_storeu_pd(M.col(4 * h + 3).data(), _mm256_permute2f128_pd(t1, t3, 0x31));
      }
      _mm256_storeu_pd(M.col(8).data(), last);
    }
  };
#endif

  // Column (a, b) of the symmetric storage (a, b in either order).
  static constexpr int sym(int a, int b) {
    return a <= b ? a * D - a * (a - 1) / 2 + (b - a) : sym(b, a);
  }

  // The general term's stresses of particle i (method/TaylorCorrection.hpp's formula).
  using GeneralStresses = TaylorStresses<D>;
  GeneralStresses generalStresses(Index i, const Mat<D>& F, const Gradients& G) const {
    return taylorTermStresses<D>(offset_[i], spread_[i], lambda_[i], mu_[i], smallStrain_[i], F, G);
  }
  // P^q = sum_a G_a sigma_a + F tau (tau for the linear-elastic material), keeping the
  // hyperstress R_a = F sigma_a (sigma_a). Not inlined: the lattice pass around its call stays
  // as it was.
  [[gnu::noinline]] Mat<D> generalStress(Index i, const Mat<D>& F, const SymMatrix& Gs) {
    const Gradients G = unpack(Gs);
    const GeneralStresses t = generalStresses(i, F, G);
    const bool small = smallStrain_[i];
    Gradients R;
    Mat<D> Pq = small ? t.tau : Mat<D>(F * t.tau);
    for (int a = 0; a < D; ++a) {
      if (!small) Pq += G[a] * t.sigma[a];
      R[a] = small ? t.sigma[a] : Mat<D>(F * t.sigma[a]);
    }
    R_[i].template topRows<D>() = symmetric(R);
    return Pq;
  }
  // V_I [1/2 sum_ab N_ab e_a : C0 : e_b + sum_a mu_a (C0 : E) : e_a]
  double generalEnergy(Index i, const Mat<D>& F, const Gradients& G) const {
    return volume_[i] * taylorTermEnergyDensity<D>(offset_[i], spread_[i], smallStrain_[i], F, G,
                                                   generalStresses(i, F, G));
  }
  // dP^q and dR_a: the plain term's formula (method/TaylorCorrection.hpp).
  TaylorLinearised<D> generalLinearised(Index i, const Mat<D>& F, const Gradients& G,
                                        const Mat<D>& dH, const Gradients& dG) const {
    const GeneralStresses t = generalStresses(i, F, G);
    return linearisedTaylorTerm<D>(offset_[i], spread_[i], lambda_[i], mu_[i], smallStrain_[i], F,
                                   G, t.sigma, t.tau, dH, dG);
  }

  // The linear-elastic material's hyperstress, e_a = sym(G_a): no P^q.
  PaddedMat<D> smallStrainHyperstress(Index i, const SymMatrix& Gs) {
    const Gradients G = unpack(Gs);
    Gradients sigma;
    for (int a = 0; a < D; ++a)
      sigma[a] = weight_[i] * stressOf(i, G[a]);
    R_[i].template topRows<D>() = symmetric(sigma);
    return PaddedMat<D>::Zero();
  }

  // C0 : sym(A)
  Mat<D> stressOf(Index i, const Mat<D>& A) const {
    const Mat<D> e = 0.5 * (A + A.transpose());
    return lambda_[i] * e.trace() * Mat<D>::Identity() + 2.0 * mu_[i] * e;
  }

  // sum_ab R_a(:, b) S(b, a) = Rs s for symmetric S: column (a, b) of Rs is R_a(:, b) + R_b(:, a)
  // (a < b) or R_a(:, a).
  static SymMatrix symmetric(const Gradients& R) {
    SymMatrix Rs;
    int t = 0;  // sym(a, b), counted: the loops stay rolled and sym() would be computed
    for (int a = 0; a < D; ++a)
      for (int b = a; b < D; ++b, ++t)
        Rs.col(t) = a == b ? Vec<D>(R[a].col(a)) : Vec<D>(R[a].col(b) + R[b].col(a));
    return Rs;
  }

  void hyperForce(std::span<const PaddedSymMatrix> R) {
    const auto& nb = ref_.neighbours;
    const Index n = ref_.particleCount();
#pragma omp parallel for schedule(static)
    for (Index i = 0; i < n; ++i) {
      PaddedVec<D> f = R[i] * sum_[i];
      const Sym* T = reverse_.row(i);
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++T)
        f.noalias() -= R[nb.neighbour[k]] * *T;
      force_[i] = volume_[i] * f.template head<D>();
    }
  }

  const ReferenceConfiguration<D>& ref_;
  const std::vector<double>& volume_;
  SharedRows<Fit> fit_;      // [g_IJ, S_IJ]
  SharedRows<Sym> reverse_;  // T_IJ = (V_J / V_I) S_JI
  std::vector<Sym> sum_;     // sum_J S_IJ
  std::vector<double> weight_, lambda_, mu_;
  std::vector<std::uint8_t> smallStrain_;  // linear-elastic material: e_a = sym(G_a)
  bool general_ = false;                   // the particles' own moments, not lattice cells'
  std::vector<Vec<D>> offset_;             // mu_I (only when general_)
  std::vector<Mat<D>> spread_;             // N_I (only when general_)
  std::vector<SymMatrix> G_;               // grad grad u, symmetric storage
  LargeArray<PaddedSymMatrix> R_;          // hyperstress, symmetric storage, padded (gathered)
  std::vector<Vec<D>> force_;
};

extern template class TaylorQuadrature<2>;
extern template class TaylorQuadrature<3>;

}  // namespace tlsph
