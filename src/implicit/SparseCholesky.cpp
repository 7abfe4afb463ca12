#include "implicit/SparseCholesky.hpp"

#include <dlfcn.h>

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

namespace {
// OpenBLAS (Debian's libblas.so.3 when libopenblas0-pthread is installed) starts its own
// threads, which spin against the OpenMP threads of the force passes between the many small
// triangular solves of the conjugate gradients (measured: 14 s of system time in 22 s of a
// modal analysis). One BLAS thread is faster overall; set it if that BLAS is the one loaded.
void singleThreadedBlas() {
  using SetThreads = void (*)(int);
  if (auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads")))
    set(1);
}
}  // namespace

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Implementation>()) {
  singleThreadedBlas();
}
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
