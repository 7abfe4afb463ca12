#include "modes/Inertia.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <vector>

#ifdef TLSPH_HAVE_CHOLMOD
#include <cholmod.h>
#else
#include <Eigen/SparseCholesky>
#endif

namespace tlsph {

namespace {

// Positions of the diagonal entries of a compressed matrix (its lower triangle is read); every
// one must be stored, since the shift changes them.
std::vector<Eigen::Index> diagonalPositions(const Inertia::Matrix& lower) {
  std::vector<Eigen::Index> diagonal(lower.cols(), -1);
  for (Eigen::Index c = 0; c < lower.cols(); ++c)
    for (Eigen::Index k = lower.outerIndexPtr()[c]; k < lower.outerIndexPtr()[c + 1]; ++k)
      if (lower.innerIndexPtr()[k] == c) diagonal[c] = k;
  for (Eigen::Index k : diagonal)
    if (k < 0) throw std::invalid_argument("Inertia: K must store every diagonal entry");
  return diagonal;
}

}  // namespace

#ifdef TLSPH_HAVE_CHOLMOD

// Supernodal Schur complements on CHOLMOD's symbolic factor. CHOLMOD orders the matrix and
// groups the columns of L into supernodes (columns with one row pattern), each a dense block:
// its diagonal block A11 and the rows below it, A21. Eliminating a supernode leaves the Schur
// complement A22 - A21 A11^-1 A21^T, whose pattern the symbolic factor already holds in the
// supernodes above, and by Haynsworth's inertia additivity
//   In(A) = In(A11) + In(A22 - A21 A11^-1 A21^T),
// so the negative eigenvalues are the sum over supernodes of those of each A11 as it stands
// when reached (a dense L D L^T with diagonal pivoting, Eigen's LDLT). Only counts are wanted,
// so no factor is kept and any pivoting inside a block is allowed. CHOLMOD's own supernodal
// numeric factorisation is L L^T only, which stops at the first negative pivot; its simplicial
// L D L^T (and Eigen's) runs column by column without the dense products, about 20 times slower
// on a beam's K.
struct Inertia::Implementation {
  cholmod_common common;
  cholmod_factor* symbolic = nullptr;
  Eigen::Index n = 0;
  std::vector<double> blocks;             // every supernode's block, column-major
  std::vector<Eigen::Index> entryTarget;  // per stored entry of K: its place in `blocks`
  std::vector<double> entryValue;
  std::vector<Eigen::Index> diagonalTarget;  // per unknown (original numbering)
  Eigen::VectorXd mass;
  std::vector<int> superOfColumn;  // permuted column -> its supernode
  std::vector<int> localRow;       // scratch: permuted row -> row within the current target

  Implementation() { cholmod_start(&common); }
  ~Implementation() {
    if (symbolic) cholmod_free_factor(&symbolic, &common);
    cholmod_finish(&common);
  }

  const int* intArray(void* p) const { return static_cast<const int*>(p); }
  int super(int s) const { return intArray(symbolic->super)[s]; }
  int rowStart(int s) const { return intArray(symbolic->pi)[s]; }
  long valueStart(int s) const { return static_cast<long>(intArray(symbolic->px)[s]); }
  const int* rows() const { return intArray(symbolic->s); }

  void analyse(Matrix& lower) {
    n = lower.cols();
    cholmod_sparse a{};
    a.nrow = a.ncol = static_cast<std::size_t>(n);
    a.nzmax = static_cast<std::size_t>(lower.nonZeros());
    a.p = lower.outerIndexPtr();
    a.i = lower.innerIndexPtr();
    a.x = lower.valuePtr();
    a.stype = -1;  // the lower triangle
    a.itype = CHOLMOD_INT;
    a.xtype = CHOLMOD_PATTERN;
    a.dtype = CHOLMOD_DOUBLE;
    a.sorted = 1;
    a.packed = 1;
    common.supernodal = CHOLMOD_SUPERNODAL;
    symbolic = cholmod_analyze(&a, &common);
    if (!symbolic || !symbolic->is_super)
      throw std::runtime_error("Inertia: CHOLMOD's supernodal analysis failed");

    const int* perm = intArray(symbolic->Perm);
    std::vector<int> position(n);  // original -> permuted
    for (Eigen::Index k = 0; k < n; ++k)
      position[perm[k]] = static_cast<int>(k);
    const int nsuper = static_cast<int>(symbolic->nsuper);
    superOfColumn.resize(n);
    for (int s = 0; s < nsuper; ++s)
      for (int c = super(s); c < super(s + 1); ++c)
        superOfColumn[c] = s;
    blocks.assign(symbolic->xsize, 0.0);
    localRow.assign(n, -1);

    // where each stored entry (r, c), r >= c, lands once permuted: the lower of the two in
    // the column of the other
    auto target = [&](int r, int c) {
      const int i = std::max(position[r], position[c]);
      const int j = std::min(position[r], position[c]);
      const int s = superOfColumn[j];
      const int* first = rows() + rowStart(s);
      const int* last = rows() + rowStart(s + 1);
      const int* at = std::lower_bound(first, last, i);
      const long nsrow = last - first;
      return static_cast<Eigen::Index>(valueStart(s) + (j - super(s)) * nsrow + (at - first));
    };
    entryTarget.resize(lower.nonZeros());
    entryValue.assign(lower.valuePtr(), lower.valuePtr() + lower.nonZeros());
    diagonalTarget.resize(n);
    for (Eigen::Index c = 0; c < n; ++c)
      for (Eigen::Index k = lower.outerIndexPtr()[c]; k < lower.outerIndexPtr()[c + 1]; ++k) {
        const int r = lower.innerIndexPtr()[k];
        // the lower triangle only, as Eigen's and CHOLMOD's lower views read a full matrix
        entryTarget[k] = r >= c ? target(r, static_cast<int>(c)) : -1;
        if (r == c) diagonalTarget[c] = entryTarget[k];
      }
  }

  long count(double sigma) {
    std::fill(blocks.begin(), blocks.end(), 0.0);
    for (std::size_t k = 0; k < entryTarget.size(); ++k)
      if (entryTarget[k] >= 0) blocks[entryTarget[k]] += entryValue[k];
    for (Eigen::Index c = 0; c < n; ++c)
      blocks[diagonalTarget[c]] -= sigma * mass[c];

    long negative = 0;
    const int nsuper = static_cast<int>(symbolic->nsuper);
    Eigen::LDLT<Eigen::MatrixXd, Eigen::Lower> pivot;
    Eigen::MatrixXd z, up, down, schur;
    for (int s = 0; s < nsuper; ++s) {
      const int nscol = super(s + 1) - super(s);
      const int nsrow = rowStart(s + 1) - rowStart(s);
      const int below = nsrow - nscol;
      Eigen::Map<Eigen::MatrixXd> block(blocks.data() + valueStart(s), nsrow, nscol);
      const Eigen::MatrixXd a11 = block.topRows(nscol).selfadjointView<Eigen::Lower>();
      pivot.compute(a11);
      const auto d = pivot.vectorD();
      for (Eigen::Index k = 0; k < d.size(); ++k) {
        if (d[k] == 0.0 || !std::isfinite(d[k])) return -1;  // sigma on an eigenvalue
        if (d[k] < 0.0) ++negative;
      }
      if (below == 0) continue;
      // A21 A11^-1 A21^T = Z^T D^-1 Z with Z = L^-1 P A21^T: the lower triangle only, as the
      // difference of two symmetric rank updates (D's positive and negative entries)
      z = pivot.transpositionsP() * block.bottomRows(below).transpose();
      pivot.matrixL().solveInPlace(z);
      const Eigen::Index positives = nscol - (d.array() < 0.0).count();
      up.resize(below, positives);
      down.resize(below, nscol - positives);
      for (Eigen::Index k = 0, p = 0, q = 0; k < nscol; ++k) {
        if (d[k] > 0.0)
          up.col(p++) = z.row(k).transpose() / std::sqrt(d[k]);
        else
          down.col(q++) = z.row(k).transpose() / std::sqrt(-d[k]);
      }
      schur.setZero(below, below);
      if (up.cols() > 0) schur.selfadjointView<Eigen::Lower>().rankUpdate(up);
      if (down.cols() > 0) schur.selfadjointView<Eigen::Lower>().rankUpdate(down, -1.0);
      // subtract the Schur complement's lower triangle from the supernodes that own its columns
      const int* sRows = rows() + rowStart(s) + nscol;
      int current = -1;
      int targetRows = 0;
      for (int k = 0; k < below; ++k) {
        const int j = sRows[k];
        const int t = superOfColumn[j];
        if (t != current) {
          current = t;
          targetRows = rowStart(t + 1) - rowStart(t);
          const int* tRows = rows() + rowStart(t);
          for (int l = 0; l < targetRows; ++l)
            localRow[tRows[l]] = l;
        }
        double* column = blocks.data() + valueStart(t) + long(j - super(t)) * targetRows;
        for (int l = k; l < below; ++l)
          column[localRow[sRows[l]]] -= schur(l, k);
      }
    }
    return negative;
  }
};

Inertia::Inertia(const Matrix& lowerK, const Eigen::VectorXd& mass)
    : impl_(std::make_unique<Implementation>()) {
  Matrix lower = lowerK;
  lower.makeCompressed();
  diagonalPositions(lower);
  impl_->mass = mass;
  impl_->analyse(lower);
}

long Inertia::factorNonZeros() const {
  return static_cast<long>(impl_->symbolic->xsize);
}

long Inertia::countBelow(double sigma) {
  const auto start = std::chrono::steady_clock::now();
  const long negative = impl_->count(sigma);
  ++factorisations_;
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return negative;
}

#else  // without CHOLMOD: Eigen's simplicial L D L^T (AMD ordering, no pivoting)

namespace {
// Eigen keeps the column counts of the symbolic factor protected; they give its size before
// the numeric factorisation is attempted.
class Factor : public Eigen::SimplicialLDLT<Inertia::Matrix, Eigen::Lower> {
 public:
  long nonZeros() const {
    return static_cast<long>(m_nonZerosPerCol.sum()) + m_nonZerosPerCol.size();
  }
};
}  // namespace

struct Inertia::Implementation {
  Matrix shifted;
  Eigen::VectorXd mass;
  std::vector<Eigen::Index> diagonal;  // position of each diagonal entry in `shifted`
  Eigen::VectorXd kDiagonal;
  Factor factor;
};

Inertia::Inertia(const Matrix& lowerK, const Eigen::VectorXd& mass)
    : impl_(std::make_unique<Implementation>()) {
  impl_->shifted = lowerK;
  impl_->shifted.makeCompressed();
  impl_->mass = mass;
  impl_->diagonal = diagonalPositions(impl_->shifted);
  impl_->kDiagonal.resize(lowerK.cols());
  for (Eigen::Index c = 0; c < lowerK.cols(); ++c)
    impl_->kDiagonal[c] = impl_->shifted.valuePtr()[impl_->diagonal[c]];
  impl_->factor.analyzePattern(impl_->shifted);
}

long Inertia::factorNonZeros() const {
  return impl_->factor.nonZeros();
}

long Inertia::countBelow(double sigma) {
  const auto start = std::chrono::steady_clock::now();
  Implementation& m = *impl_;
  for (std::size_t c = 0; c < m.diagonal.size(); ++c)
    m.shifted.valuePtr()[m.diagonal[c]] = m.kDiagonal[c] - sigma * m.mass[c];
  m.factor.factorize(m.shifted);
  ++factorisations_;
  long negative = -1;
  if (m.factor.info() == Eigen::Success) negative = (m.factor.vectorD().array() < 0.0).count();
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return negative;
}

#endif

Inertia::~Inertia() = default;

}  // namespace tlsph
