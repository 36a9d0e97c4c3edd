#include "model/runtime.h"

#include <dlfcn.h>
#include <torch/torch.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "absl/strings/str_cat.h"

namespace stylus::model {

void SetComputeThreads(int threads) {
  at::set_num_threads(
      threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
}

int ComputeThreads() { return at::get_num_threads(); }

void InitComputeThreadsHere() { at::init_num_threads(); }

BlasReport AdviseBlas(const std::string& library, const std::string& kernel,
                      const std::string& cpu_flags) {
  BlasReport r{library, kernel, "", ""};
  std::set<std::string> flags;
  std::istringstream in(cpu_flags);
  for (std::string f; in >> f;) flags.insert(f);
  // Haswell (AVX2, FMA) is the kernel to ask for: some OpenBLAS builds
  // compute wrong results with SkylakeX on some AVX-512 CPUs.
  if (flags.count("avx2") && flags.count("fma")) r.best = "Haswell";
  std::string k = kernel;
  for (char& c : k) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  // OpenBLAS kernels that use AVX2 and FMA or better.
  static const std::set<std::string> modern = {"haswell", "skylakex", "cooperlake",
                                               "sapphirerapids", "zen"};
  if (!k.empty() && !r.best.empty() && !modern.count(k)) {
    r.warning = absl::StrCat("OpenBLAS runs its ", kernel,
                             " kernel on a CPU with AVX2: matrix products may be several "
                             "times slower; set "
                             "OPENBLAS_CORETYPE=",
                             r.best, " in the server's environment (docs/service.md, BLAS kernel)");
  }
  return r;
}

BlasReport DescribeBlas() {
  std::string library = "unknown", kernel;
  using Name = char* (*)();
  if (auto config = reinterpret_cast<Name>(dlsym(RTLD_DEFAULT, "openblas_get_config"))) {
    library = config();
  }
  if (auto core = reinterpret_cast<Name>(dlsym(RTLD_DEFAULT, "openblas_get_corename"))) {
    kernel = core();
  }
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string flags;
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("flags", 0) == 0) {
      flags = line.substr(line.find(':') + 1);
      break;
    }
  }
  return AdviseBlas(library, kernel, flags);
}

}  // namespace stylus::model
