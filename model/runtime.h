// Process-wide LibTorch settings. Call once at start-up, before any model runs
// (architecture rule 5: changing thread counts later is unsafe in LibTorch).
#ifndef STYLUS_MODEL_RUNTIME_H_
#define STYLUS_MODEL_RUNTIME_H_

#include <string>

namespace stylus::model {

// What LibTorch's matrix products run on, for the start-up line: the BLAS
// library and its kernel (OpenBLAS picks one for the CPU at load time; on
// a virtual machine whose CPU reports a generic model it may pick its
// oldest, several times slower), the kernel this CPU's flags allow, and
// advice when the two are far apart.
struct BlasReport {
  std::string library;  // e.g. "OpenBLAS 0.3.21 ...", or "unknown".
  std::string kernel;   // e.g. "Haswell", or "" when the library does not say.
  std::string best;     // "Haswell" (AVX2 and FMA), or "".
  std::string warning;  // Set when the kernel predates AVX2 on a CPU with it.
};
BlasReport DescribeBlas();
// The decision behind DescribeBlas, from a kernel name and the CPU's flags
// (the "flags" line of /proc/cpuinfo).
BlasReport AdviseBlas(const std::string& library, const std::string& kernel,
                      const std::string& cpu_flags);

// Intra-op threads for tensor operations; 0 means one per core.
void SetComputeThreads(int threads);
int ComputeThreads();

// Applies the SetComputeThreads count to the calling thread: threads started
// by the program (the server's executor and batcher) call it first. Without
// it, BLAS products run from such a thread are split over every core
// (OpenMP's default for a new thread), whatever the count says.
void InitComputeThreadsHere();

}  // namespace stylus::model

#endif  // STYLUS_MODEL_RUNTIME_H_
