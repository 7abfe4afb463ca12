#include "tlsph/SparseCholesky.hpp"

#ifdef TLSPH_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#else
#include <Eigen/SparseCholesky>
#endif

namespace tlsph {

#ifdef TLSPH_HAVE_CHOLMOD
namespace {
// Eigen keeps the cholmod_factor protected; its size is the factor's memory.
class SupernodalFactor : public Eigen::CholmodSupernodalLLT<SparseCholesky::Matrix, Eigen::Lower> {
 public:
  const cholmod_factor* factorPtr() const { return m_cholmodFactor; }
};
}  // namespace
#endif

struct SparseCholesky::Implementation {
#ifdef TLSPH_HAVE_CHOLMOD
  SupernodalFactor factor;
#else
  Eigen::SimplicialLDLT<Matrix, Eigen::Lower> factor;
#endif
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Implementation>()) {}
SparseCholesky::~SparseCholesky() = default;

bool SparseCholesky::factorise(const Matrix& lower) {
  if (!analysed_) {
    impl_->factor.analyzePattern(lower);
    analysed_ = true;
  }
  impl_->factor.factorize(lower);
  return impl_->factor.info() == Eigen::Success;
}

Eigen::VectorXd SparseCholesky::solve(const Eigen::VectorXd& b) const {
  return impl_->factor.solve(b);
}

long SparseCholesky::factorNonZeros() const {
#ifdef TLSPH_HAVE_CHOLMOD
  const cholmod_factor* L = impl_->factor.factorPtr();
  if (!L) return 0;
  return L->is_super ? static_cast<long>(L->xsize) : static_cast<long>(L->nzmax);
#else
  return static_cast<long>(impl_->factor.matrixL().nestedExpression().nonZeros());
#endif
}

std::string SparseCholesky::name() {
#ifdef TLSPH_HAVE_CHOLMOD
  return "CHOLMOD supernodal Cholesky";
#else
  return "Eigen SimplicialLDLT";
#endif
}

}  // namespace tlsph
