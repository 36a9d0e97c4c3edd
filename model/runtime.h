// Process-wide LibTorch settings. Call once at start-up, before any model runs
// (architecture rule 5: changing thread counts later is unsafe in LibTorch).
#ifndef STYLUS_MODEL_RUNTIME_H_
#define STYLUS_MODEL_RUNTIME_H_

namespace stylus::model {

// Intra-op threads for tensor operations; 0 means one per core.
void SetComputeThreads(int threads);
int ComputeThreads();

}  // namespace stylus::model

#endif  // STYLUS_MODEL_RUNTIME_H_
