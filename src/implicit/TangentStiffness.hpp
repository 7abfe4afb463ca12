// The tangent stiffness K = -df/du of the internal force on the unknowns (DofMap), i.e. the
// Hessian T^T (d2E/du2) T of the discrete energy E = sum_I V_I psi(F_I) + E_hg (docs/method.md
// section 2), with prescribed particles eliminated and mirrored ghosts chained to the particles
// they follow. Two forms:
//   apply(v):   K v exactly, matrix-free, at the cost of one force pass:
//               dF_I = sum_J (v_J - v_I) (x) g_IJ,  dP_I = A_I : dF_I  (A = dP/dF),
//               and E_hg, quadratic in u, gives its exact part by evaluating the penalty on v.
//   assemble(): a sparse matrix (lower triangle) with the exact strain part
//               K_pq = sum_I V_I B_Ip^T A_I B_Iq,  B_Ip = b_Ip (x) 1  (b: I's gradient vectors
//               reduced through the DofMap), and, for the penalty, the Hessian of
//               1/4 sum_I sum_J k_IJ |u_I - u_J - H_I X_IJ|^2, which bounds the exact E_hg from
//               above (Young's inequality on the H_I X . H_J X cross term) but, unlike it, stays
//               within I's own stencil: the same sparsity as the strain part (neighbours of
//               neighbours) instead of three kernel radii. Exact when the penalty is off; with
//               it, the preconditioner of the exact operator (NewtonSolver).
// The product is in every conjugate-gradient iteration, so its penalty and Taylor parts run on
// the fast passes (fast/EnergyHourglass on the direction; fast/TaylorQuadrature::linearise,
// method/TaylorCorrection::linearised fused); the tests hold K v to central differences of the
// plain force of method/PairForces.
#pragma once

#include <Eigen/Sparse>
#include <algorithm>
#include <cstdint>
#include <memory>
#include <span>
#include <variant>
#include <vector>

#include "fast/EnergyHourglass.hpp"
#include "fast/TaylorQuadrature.hpp"
#include "implicit/DofMap.hpp"
#include "materials/Material.hpp"
#include "method/HourglassStiffness.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/Errors.hpp"
#include "model/PairTerms.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D>
class TangentStiffness {
 public:
  static constexpr int DD = D * D;
  using Modulus = Eigen::Matrix<double, DD, DD>;  // dP/dF, index i + D j of (i, j)
  using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

  // The mirrored ghosts of `dofs` carry no strain energy of their own. With the Taylor
  // quadrature, apply() includes its linearised term (updateQuadrature()); the assembly leaves
  // it out, so assemblyExact() is false.
  TangentStiffness(const ReferenceConfiguration<D>& ref, const std::vector<Material>& materials,
                   const std::vector<std::uint16_t>& materialOf, const std::vector<double>& volume,
                   const HourglassSettings& hourglass, const DofMap<D>& dofs,
                   Quadrature quadrature = Quadrature::Nodal,
                   const QuadratureMoments<D>& moments = {})
      : ref_(ref),
        materials_(materials),
        volume_(volume),
        hourglass_(hourglass),
        dofs_(dofs),
        n_(ref.particleCount()) {
    const std::vector<Index> passive = dofs.ghostParticles();
    std::vector<std::uint8_t> isPassive(n_, 0);
    for (Index i : passive)
      isPassive.at(i) = 1;
    groups_.resize(materials.size());
    for (Index i = 0; i < n_; ++i)
      if (!isPassive[i]) groups_.at(materialOf[i]).push_back(i);
    modulus_.assign(n_, Modulus::Zero());
    hasEnergy_.assign(n_, 0);
    for (Index i = 0; i < n_; ++i)
      hasEnergy_[i] = !isPassive[i];
    if (hourglass.enabled()) {
      if (hourglass.form != HourglassForm::Energy)
        throw SetupError(
            "the tangent stiffness needs the hourglass penalty in its energy form ([hourglass] "
            "form = energy): the textbook force (6.80)-(6.81) is not the gradient of an energy");
      c_ = hourglassPairCoefficients(ref, materials, materialOf, volume, hourglass.alpha,
                                     passive.empty() ? std::vector<std::uint8_t>{} : isPassive);
      penalty_ = std::make_unique<EnergyHourglass<D>>(ref, c_, volume);
      separate_ = hourglass.gradient == HourglassGradient::Linear && !ref.linearGradient.empty();
      if (separate_) {
        linearReverse_ = reverseVectors<D>(ref.neighbours, ref.linearGradient, volume, ref.rows());
        linearSum_.assign(n_, Vec<D>::Zero());
        for (Index i = 0; i < n_; ++i)
          for (Index k = ref.neighbours.offset[i]; k < ref.neighbours.offset[i + 1]; ++k)
            linearSum_[i] += ref.linearGradient[k];
        hourglassH_.assign(n_, Mat<D>::Zero());
      }
      penaltyStress_.assign(n_, Mat<D>::Zero());
    }
    if (quadrature == Quadrature::Taylor) {
      quadrature_ = std::make_unique<TaylorQuadrature<D>>(ref, materials, materialOf, volume,
                                                          isPassive, moments);
      quadratureF_.assign(n_, Mat<D>::Identity());
      quadratureG_.assign(n_, TaylorQuadrature<D>::SymMatrix::Zero());
    }
    full_.assign(n_, Vec<D>::Zero());
    dF_.assign(n_, Mat<D>::Zero());
    dS_.assign(n_, Mat<D>::Zero());
    df_.assign(n_, Vec<D>::Zero());
  }

  // True when assemble() is the exact K (no penalty); otherwise it bounds the penalty's part.
  bool assemblyExact() const { return !hourglass_.enabled() && !quadrature_; }
  Index size() const { return D * dofs_.size(); }

  // The material tangents A_I = dP/dF at the deformation gradients F (every particle's; the
  // passive ones are not used).
  void update(std::span<const Mat<D>> F);
  // The state of the quadrature correction (TaylorQuadrature; F and its second gradients from
  // the last force pass); the assembled matrix leaves that term out (a preconditioner then).
  void updateQuadrature(const TaylorQuadrature<D>* q, std::span<const Mat<D>> F) {
    if (!quadrature_ || !q) return;
    quadratureF_.assign(F.begin(), F.end());
    quadratureG_ = q->secondGradients();
  }
  // The same from saved second gradients (a restart).
  void updateQuadrature(const std::vector<typename TaylorQuadrature<D>::SymMatrix>& G,
                        std::span<const Mat<D>> F) {
    if (!quadrature_ || G.empty()) return;
    quadratureF_.assign(F.begin(), F.end());
    quadratureG_ = G;
  }

  // Kv = K v, exactly (v and Kv: D values per unknown, stacked).
  // Which part of K a product takes: all of it, the strain energy's, or the penalty's.
  enum class Part { All, Strain, Penalty };
  void apply(const Eigen::VectorXd& v, Eigen::VectorXd& Kv, Part part = Part::All);

  // The sparse matrix described at the top, lower triangle only (use selfadjointView<Lower>).
  // The pattern is built on the first call.
  const SparseMatrix& assemble();
  // The diagonal blocks of assemble()'s matrix, one D x D block per unknown, without building
  // the matrix (the block-Jacobi part of the multigrid smoother). Reproducible bit for bit on
  // any thread count.
  std::vector<Mat<D>> diagonalBlocks() const;
  // Adds d (one value per unknown) to the diagonal of the last assembled matrix, e.g. -sigma
  // times the masses for the shifted matrix K - sigma M of a modal analysis.
  void addToDiagonal(const Eigen::VectorXd& d);

 private:
  // Particle I's stencil {I} + N(I) expressed on the unknowns: per unknown p (sorted),
  //   b_p = sum of w b_a, bh_p likewise with the penalty's vectors, self_p = w of I itself,
  // over the terms (p, w) of each member a, with b_I = -G_I and b_J = g_IJ.
  struct Stencil {
    std::vector<Index> dof;
    std::vector<Vec<D>> b, bh;
    std::vector<double> self;
    void clear() {
      dof.clear();
      b.clear();
      bh.clear();
      self.clear();
    }
    Index position(Index d) const {
      return static_cast<Index>(std::lower_bound(dof.begin(), dof.end(), d) - dof.begin());
    }
  };

  void reducedStencil(Index i, Stencil& s) const;
  // The penalty's residual coefficients C(p, J) of I's stencil (assemble(), diagonalBlocks()).
  void penaltyCoefficients(Index i, const Stencil& s, Eigen::MatrixXd& C) const;

  // B = b (x) 1_D: vec(u b^T) = B u.
  using Kronecker = Eigen::Matrix<double, DD, D>;
  static Kronecker kroneckerIdentity(const Vec<D>& b);

  // Block column q holds the sorted block rows p >= q of every stencil sharing both; scalar
  // column D q + k stores rows D p + i at blockStart_[q] D^2 + k D L_q + D idx(p) + i.
  void buildPattern();
  void addBlock(Index p, Index q, const Mat<D>& block);

  const ReferenceConfiguration<D>& ref_;
  const std::vector<Material>& materials_;
  const std::vector<double>& volume_;
  HourglassSettings hourglass_;
  const DofMap<D>& dofs_;
  Index n_;
  std::vector<std::vector<Index>> groups_;  // energy particles per material
  std::vector<std::uint8_t> hasEnergy_;
  std::vector<Modulus> modulus_;
  PairArray<double> c_;  // the penalty's c_IJ
  std::unique_ptr<EnergyHourglass<D>> penalty_;
  std::unique_ptr<TaylorQuadrature<D>> quadrature_;
  std::vector<Mat<D>> quadratureF_;
  std::vector<typename TaylorQuadrature<D>::SymMatrix> quadratureG_;
  bool separate_ = false;            // the penalty compares with the linear F (its own vectors)
  PairArray<Vec<D>> linearReverse_;  // t^lin_IJ
  std::vector<Vec<D>> linearSum_;    // G^lin_I
  std::vector<Mat<D>> hourglassH_, penaltyStress_;
  std::vector<Vec<D>> full_, df_;
  std::vector<Mat<D>> dF_, dS_;  // per particle: dH = dF and A : dH
  std::vector<Index> blockStart_, blockRows_;
  std::vector<Index> stencilFirst_, stencilLast_;  // per particle: its stencil's dof range
  SparseMatrix matrix_;
};

extern template class TangentStiffness<2>;
extern template class TangentStiffness<3>;

}  // namespace tlsph
