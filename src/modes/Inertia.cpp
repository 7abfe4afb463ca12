#include "modes/Inertia.hpp"

#include <Eigen/SparseCholesky>
#include <chrono>

namespace tlsph {

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
  const Eigen::Index n = lowerK.cols();
  impl_->diagonal.assign(n, -1);
  impl_->kDiagonal.setZero(n);
  for (Eigen::Index c = 0; c < n; ++c)
    for (Eigen::Index k = impl_->shifted.outerIndexPtr()[c];
         k < impl_->shifted.outerIndexPtr()[c + 1]; ++k)
      if (impl_->shifted.innerIndexPtr()[k] == c) {
        impl_->diagonal[c] = k;
        impl_->kDiagonal[c] = impl_->shifted.valuePtr()[k];
      }
  for (Eigen::Index c = 0; c < n; ++c)
    if (impl_->diagonal[c] < 0)
      throw std::invalid_argument("Inertia: K must store every diagonal entry");
  impl_->factor.analyzePattern(impl_->shifted);
}

Inertia::~Inertia() = default;

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

}  // namespace tlsph
