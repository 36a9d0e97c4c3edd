// Process-wide LibTorch settings. Call once at start-up, before any model runs
// (architecture rule 5: changing thread counts later is unsafe in LibTorch).
#ifndef STYLUS_MODEL_RUNTIME_H_
#define STYLUS_MODEL_RUNTIME_H_

namespace stylus::model {

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
