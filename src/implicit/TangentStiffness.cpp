// TangentStiffness (see the header): the linearised force pass, the assembly and its pattern.
// Compiled once for 2D and 3D.
#include "implicit/TangentStiffness.hpp"

#include <utility>

#include "execution/Threads.hpp"

namespace tlsph {

template <int D>
void TangentStiffness<D>::update(std::span<const Mat<D>> F) {
  for (std::size_t m = 0; m < materials_.size(); ++m)
    std::visit(
        [&](const auto& model) {
          const auto& group = groups_[m];
          const Index count = static_cast<Index>(group.size());
#pragma omp parallel for schedule(static)
          for (Index p = 0; p < count; ++p)
            modulus_[group[p]] = tangentModulus<D>(model, F[group[p]]);
        },
        materials_[m]);
}

template <int D>
void TangentStiffness<D>::apply(const Eigen::VectorXd& v, Eigen::VectorXd& Kv, Part part) {
  const auto& nb = ref_.neighbours;
  dofs_.expand(v, full_);
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < n_; ++i) {
    const Vec<D> vi = full_[i];
    Mat<D> dH = Mat<D>::Zero(), dHh = Mat<D>::Zero();
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Vec<D> dv = full_[nb.neighbour[k]] - vi;
      dH.noalias() += dv * ref_.correctedGradient[k].transpose();  // (6.69), linearised
      if (separate_) dHh.noalias() += dv * ref_.linearGradient[k].transpose();
    }
    dF_[i] = dH;  // the penalty takes the gradient itself (1 + dH would round dH off)
    if (separate_) hourglassH_[i] = dHh;
    if (hasEnergy_[i] && part != Part::Penalty) {
      Eigen::Map<Eigen::Matrix<double, DD, 1>>(dS_[i].data()) =
          modulus_[i] * Eigen::Map<const Eigen::Matrix<double, DD, 1>>(dH.data());  // A : dF
    } else {
      dS_[i].setZero();
    }
  }
  const std::vector<Mat<D>>* S = &dS_;
  const bool penalty = penalty_ && part != Part::Strain;
  if (penalty) {
    // E_hg is quadratic in u: its force at v is K_hg v.
    if (separate_) {
      penalty_->template evaluate<true>(
          std::span<const Vec<D>>(full_), std::span<const Mat<D>>(hourglassH_),
          static_cast<const Mat<D>*>(nullptr), std::span<Mat<D>>(penaltyStress_));
    } else {
      penalty_->template evaluate<true>(std::span<const Vec<D>>(full_),
                                        std::span<const Mat<D>>(dF_), dS_.data(),
                                        std::span<Mat<D>>(penaltyStress_));
      S = &penaltyStress_;
    }
  }
  const bool quadrature = quadrature_ && part != Part::Penalty;
  if (quadrature)
    quadrature_->linearise(full_, dF_, quadratureF_, quadratureG_,
                           S == &penaltyStress_ ? penaltyStress_ : dS_);
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < n_; ++i) {
    const auto& St = *S;
    // f_I = V_I (S_I G_I - sum_J S_J t_IJ), linearised
    Vec<D> f = St[i] * ref_.correctedGradientSum[i];
    const bool linearPenalty = separate_ && penalty;
    if (linearPenalty) f += penaltyStress_[i] * linearSum_[i];
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      f.noalias() -= St[nb.neighbour[k]] * ref_.reverseGradient[k];
      if (linearPenalty) f.noalias() -= penaltyStress_[nb.neighbour[k]] * linearReverse_[k];
    }
    df_[i] = volume_[i] * f;
    if (penalty) df_[i] += penalty_->springForce(i);
    if (quadrature) df_[i] += quadrature_->force(i);
  }
  dofs_.gather(df_, Kv);
  Kv = -Kv;
}

// Each thread owns a range of block columns and adds only to those (no atomics), taking the
// particles in index order: every entry sums its contributions in the same order whatever the
// thread count, so the matrix, and a Newton solve preconditioned by it, are reproducible bit
// for bit (checkpoint/restart relies on that). A particle whose stencil straddles two ranges
// is visited by both threads, each adding its own columns.
template <int D>
const typename TangentStiffness<D>::SparseMatrix& TangentStiffness<D>::assemble() {
  if (matrix_.rows() == 0) buildPattern();
  std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), 0.0);
  const auto& nb = ref_.neighbours;
  const Index nd = dofs_.size();
#pragma omp parallel
  {
    const ThreadSlot slot = threadSlot();
    const int thread = slot.thread, threads = slot.threads;
    // Block columns [first, last): an equal share of the stored blocks.
    auto columnAt = [&](int t) {
      const Index target = blockStart_[nd] * t / threads;
      return static_cast<Index>(std::lower_bound(blockStart_.begin(), blockStart_.end(), target) -
                                blockStart_.begin());
    };
    const Index first = std::min(columnAt(thread), nd);
    const Index last = thread + 1 == threads ? nd : std::min(columnAt(thread + 1), nd);
    Stencil s;
    std::vector<Eigen::Matrix<double, DD, D>> AB;
    Eigen::MatrixXd C, CK;
    for (Index i = 0; i < n_; ++i) {
      if (stencilLast_[i] < first || stencilFirst_[i] >= last) continue;
      reducedStencil(i, s);
      const Index m = static_cast<Index>(s.dof.size());
      if (m == 0) continue;
      // This thread's columns of the stencil (sorted by dof): q in [q0, q1).
      const Index q0 = s.position(first), q1 = s.position(last);
      // local(p, q) blocks, p >= q in dof order (the stencil is sorted by dof)
      if (hasEnergy_[i]) {
        AB.resize(m);
        for (Index q = q0; q < q1; ++q)
          AB[q] = modulus_[i] * kroneckerIdentity(s.b[q]);  // A B_q
      }
      const bool penalty = penalty_ != nullptr;
      const Index count = nb.offset[i + 1] - nb.offset[i];
      if (penalty) {
        penaltyCoefficients(i, s, C);
        CK = C;
        for (Index k = 0; k < count; ++k)
          CK.col(k) *= 0.5 * volume_[i] * c_[nb.offset[i] + k];  // 1/2 k_IJ
      }
      for (Index q = q0; q < q1; ++q)
        for (Index p = q; p < m; ++p) {
          Mat<D> block = Mat<D>::Zero();
          if (hasEnergy_[i]) {
            for (int j = 0; j < D; ++j)
              block.noalias() += s.b[p][j] * AB[q].template middleRows<D>(D * j);
            block *= volume_[i];
          }
          if (penalty) block.diagonal().array() += CK.row(p).dot(C.row(q));
          addBlock(s.dof[p], s.dof[q], block);
        }
    }
  }
  return matrix_;
}

template <int D>
std::vector<Mat<D>> TangentStiffness<D>::diagonalBlocks() const {
  const auto& nb = ref_.neighbours;
  const Index nd = dofs_.size();
  std::vector<Mat<D>> diagonal(nd, Mat<D>::Zero());
  // Each particle's stencil spans the unknowns of I and its neighbours: [lo, hi].
  std::vector<Index> lo(n_, nd), hi(n_, -1);
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < n_; ++i) {
    auto widen = [&](Index particle) {
      auto [t, end] = dofs_.terms(particle);
      for (; t != end; ++t) {
        lo[i] = std::min(lo[i], t->dof);
        hi[i] = std::max(hi[i], t->dof);
      }
    };
    widen(i);
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      widen(nb.neighbour[k]);
  }
  // As in assemble(): each thread owns a range of unknowns and takes the particles in order.
#pragma omp parallel
  {
    const ThreadSlot slot = threadSlot();
    const int thread = slot.thread, threads = slot.threads;
    const Index first = nd * thread / threads, last = nd * (thread + 1) / threads;
    Stencil s;
    Eigen::MatrixXd C;
    for (Index i = 0; i < n_; ++i) {
      if (hi[i] < first || lo[i] >= last) continue;
      reducedStencil(i, s);
      if (penalty_) penaltyCoefficients(i, s, C);
      const Index m = static_cast<Index>(s.dof.size());
      for (Index p = s.position(first); p < m && s.dof[p] < last; ++p) {
        Mat<D> block = Mat<D>::Zero();
        if (hasEnergy_[i]) {
          const Kronecker AB = modulus_[i] * kroneckerIdentity(s.b[p]);
          for (int j = 0; j < D; ++j)
            block.noalias() += s.b[p][j] * AB.template middleRows<D>(D * j);
          block *= volume_[i];
        }
        if (penalty_) {
          // 1/2 V_I sum_J k_IJ C(p, J)^2, as in assemble()
          double sum = 0.0;
          for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
            sum += c_[k] * C(p, k - nb.offset[i]) * C(p, k - nb.offset[i]);
          block.diagonal().array() += 0.5 * volume_[i] * sum;
        }
        diagonal[s.dof[p]] += block;
      }
    }
  }
  return diagonal;
}

// C(p, J) = coefficient of u_p in r_IJ = u_I - u_J - H_I X_IJ (reduced to I's stencil).
template <int D>
void TangentStiffness<D>::penaltyCoefficients(Index i, const Stencil& s, Eigen::MatrixXd& C) const {
  const auto& nb = ref_.neighbours;
  const Index m = static_cast<Index>(s.dof.size());
  C.setZero(m, nb.count(i));
  for (Index p = 0; p < m; ++p)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      C(p, k - nb.offset[i]) = s.self[p] - s.bh[p].dot(ref_.separation[k]);
  for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
    auto [t, end] = dofs_.terms(nb.neighbour[k]);
    for (; t != end; ++t)
      C(s.position(t->dof), k - nb.offset[i]) -= t->weight;
  }
}

template <int D>
void TangentStiffness<D>::reducedStencil(Index i, Stencil& s) const {
  const auto& nb = ref_.neighbours;
  s.clear();
  auto add = [&](Index particle, const Vec<D>& b, const Vec<D>& bh, bool self) {
    auto [t, end] = dofs_.terms(particle);
    for (; t != end; ++t) {
      auto at = std::find(s.dof.begin(), s.dof.end(), t->dof);
      std::size_t p = at - s.dof.begin();
      if (at == s.dof.end()) {
        s.dof.push_back(t->dof);
        s.b.push_back(Vec<D>::Zero());
        s.bh.push_back(Vec<D>::Zero());
        s.self.push_back(0.0);
      }
      s.b[p] += t->weight * b;
      s.bh[p] += t->weight * bh;
      if (self) s.self[p] += t->weight;
    }
  };
  const bool linear = separate_;
  Vec<D> Gh = Vec<D>::Zero();
  if (linear)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      Gh += ref_.linearGradient[k];
  else
    Gh = ref_.correctedGradientSum[i];
  add(i, -ref_.correctedGradientSum[i], -Gh, true);
  for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
    add(nb.neighbour[k], ref_.correctedGradient[k],
        linear ? ref_.linearGradient[k] : ref_.correctedGradient[k], false);
  // sort by dof
  std::vector<Index> order(s.dof.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    order[k] = static_cast<Index>(k);
  std::sort(order.begin(), order.end(), [&](Index a, Index b) { return s.dof[a] < s.dof[b]; });
  Stencil sorted;
  for (Index k : order) {
    sorted.dof.push_back(s.dof[k]);
    sorted.b.push_back(s.b[k]);
    sorted.bh.push_back(s.bh[k]);
    sorted.self.push_back(s.self[k]);
  }
  s = std::move(sorted);
}

template <int D>
typename TangentStiffness<D>::Kronecker TangentStiffness<D>::kroneckerIdentity(const Vec<D>& b) {
  Eigen::Matrix<double, DD, D> B = Eigen::Matrix<double, DD, D>::Zero();
  for (int j = 0; j < D; ++j)
    B.template middleRows<D>(D * j).diagonal().setConstant(b[j]);
  return B;
}

template <int D>
void TangentStiffness<D>::buildPattern() {
  const Index nd = dofs_.size();
  std::vector<std::vector<Index>> rows(nd);
  Stencil s;
  stencilFirst_.assign(n_, nd);
  stencilLast_.assign(n_, -1);
  for (Index i = 0; i < n_; ++i) {
    reducedStencil(i, s);
    if (!s.dof.empty()) {
      stencilFirst_[i] = s.dof.front();
      stencilLast_[i] = s.dof.back();
    }
    for (std::size_t q = 0; q < s.dof.size(); ++q)
      for (std::size_t p = q; p < s.dof.size(); ++p)
        rows[s.dof[q]].push_back(s.dof[p]);
  }
  blockStart_.assign(nd + 1, 0);
  blockRows_.clear();
  for (Index q = 0; q < nd; ++q) {
    auto& r = rows[q];
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    blockStart_[q + 1] = blockStart_[q] + static_cast<Index>(r.size());
    blockRows_.insert(blockRows_.end(), r.begin(), r.end());
    std::vector<Index>().swap(r);
  }
  const Index size = D * nd;
  matrix_.resize(size, size);
  matrix_.resizeNonZeros(static_cast<Eigen::Index>(blockStart_[nd]) * DD);
  int* outer = matrix_.outerIndexPtr();
  int* inner = matrix_.innerIndexPtr();
  for (Index q = 0; q < nd; ++q) {
    const Index L = blockStart_[q + 1] - blockStart_[q];
    for (int k = 0; k < D; ++k) {
      const Index start = blockStart_[q] * DD + k * D * L;
      outer[D * q + k] = start;
      for (Index r = 0; r < L; ++r)
        for (int i = 0; i < D; ++i)
          inner[start + D * r + i] = D * blockRows_[blockStart_[q] + r] + i;
    }
  }
  outer[size] = blockStart_[nd] * DD;
}

template <int D>
void TangentStiffness<D>::addBlock(Index p, Index q, const Mat<D>& block) {
  const auto first = blockRows_.begin() + blockStart_[q];
  const auto last = blockRows_.begin() + blockStart_[q + 1];
  const Index r = static_cast<Index>(std::lower_bound(first, last, p) - first);
  const Index L = blockStart_[q + 1] - blockStart_[q];
  double* values = matrix_.valuePtr();
  for (int k = 0; k < D; ++k) {
    const Index start = blockStart_[q] * DD + k * D * L + D * r;
    for (int i = 0; i < D; ++i)
      values[start + i] += block(i, k);
  }
}

template <int D>
void TangentStiffness<D>::addToDiagonal(const Eigen::VectorXd& d) {
  // The diagonal block (q, q) is the first block row of block column q.
  double* values = matrix_.valuePtr();
  for (Index q = 0; q < dofs_.size(); ++q) {
    const Index L = blockStart_[q + 1] - blockStart_[q];
    for (int k = 0; k < D; ++k)
      values[blockStart_[q] * DD + k * D * L + k] += d[D * q + k];
  }
}

template class TangentStiffness<2>;
template class TangentStiffness<3>;

}  // namespace tlsph
