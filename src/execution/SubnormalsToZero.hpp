// Subnormal numbers flushed to zero for the duration of an explicit step.
//
// A load applied to a body at rest starts a wave whose numerical precursor decays
// geometrically ahead of it: a few particle layers ahead of the front every value of the pair
// loops passes through the subnormal range (below 2.2e-308), where an x86 core takes a
// microcode assist (on the order of a hundred cycles) for each operation that reads or
// produces one (the 10^5-particle benchmark beam's steps take 25 % less time with them
// flushed, docs/performance.md). A value below 2.2e-308 of a quantity whose
// scale is 1e-12 to 1e9 in SI units is nothing a result can show, so the step computes with
// them as zero: FTZ (results) and DAZ (operands) on x86-64, FZ on AArch64 (written, not run
// here), on the calling thread and on every thread of the OpenMP team. The previous mode is
// restored afterwards, so code around a step computes as before. Every force of an explicit
// run is computed in this mode (the step, the first forces, a restored state's, reevaluate):
// a restart recomputes exactly the bits the uninterrupted run had. The guard is on the whole
// step rather than inside TlsphForces::compute because the kicks make them too (half a step
// times a tiny acceleration).
#pragma once

#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>
#endif

namespace tlsph {

class SubnormalsToZero {
 public:
  SubnormalsToZero() {
    previous_ = readMode();
#pragma omp parallel
    writeMode(readMode() | kFlushBits);
  }
  ~SubnormalsToZero() {
    const unsigned long restore = previous_ & kFlushBits;
#pragma omp parallel
    writeMode((readMode() & ~kFlushBits) | restore);
  }
  SubnormalsToZero(const SubnormalsToZero&) = delete;
  SubnormalsToZero& operator=(const SubnormalsToZero&) = delete;

  // True where the build can set the mode (x86-64 and AArch64); elsewhere the guard does
  // nothing and subnormals are computed as the hardware does.
  static constexpr bool supported() {
    return kFlushBits != 0;
  }

 private:
#if defined(__SSE2__) || defined(_M_X64)
  static constexpr unsigned long kFlushBits = 0x8040;  // MXCSR: FTZ (bit 15), DAZ (bit 6)
  static unsigned long readMode() {
    return _mm_getcsr();
  }
  static void writeMode(unsigned long mode) {
    _mm_setcsr(static_cast<unsigned>(mode));
  }
#elif defined(__aarch64__)
  static constexpr unsigned long kFlushBits = 1ul << 24;  // FPCR: FZ
  static unsigned long readMode() {
    unsigned long fpcr;
    __asm__ __volatile__("mrs %0, fpcr" : "=r"(fpcr));
    return fpcr;
  }
  static void writeMode(unsigned long mode) {
    __asm__ __volatile__("msr fpcr, %0" : : "r"(mode));
  }
#else
  static constexpr unsigned long kFlushBits = 0;
  static unsigned long readMode() {
    return 0;
  }
  static void writeMode(unsigned long) {}
#endif
  unsigned long previous_ = 0;
};

}  // namespace tlsph
