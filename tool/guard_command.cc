// train-guard: the content guard of a contrastive package.
#include <cstdio>

#include "absl/strings/str_format.h"
#include "model/content_guard.h"
#include "model/runtime.h"
#include "tool/cli_support.h"

namespace stylus::tool {

int TrainGuard(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool train-guard --model DIR --data DIR... [--iters 3000]\n"
      "         [--batch 32] [--seed S] [--threads N]\n\n"
      "Trains the content guard of the contrastive package DIR: a classifier of\n"
      "the action, on the labelled training split of the --data directories in\n"
      "the package's own features, and writes guard.pt and guard.txt into DIR.\n"
      "Prints its clip-level accuracy on the held-out split.\n"
      "The package uses it when its config.txt says `content_guard = 1`: a\n"
      "whole-clip transfer the guard reads as another action than its content\n"
      "clip is made again in the residual form at each of `guard_strengths`\n"
      "(default 1,0.7,0.4), giving up style until the action reads right\n"
      "(docs/contrastive.md).\n";
  int code = 0;
  auto args = ParseOrExit("train-guard", argv,
                          {{"model", "data", "iters", "batch", "seed", "threads"}, {}}, kHelp,
                          &code);
  if (!args) return code;
  model::ContentGuardTrainOptions o;
  o.model = args->Get("model");
  o.data = args->All("data");
  if (o.model.empty() || o.data.empty()) {
    std::fprintf(stderr, "stylus-tool train-guard: --model and --data are required\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<int> iters = args->GetInt("iters", o.iterations),
                      batch = args->GetInt("batch", o.batch), seed = args->GetInt("seed", 1),
                      threads = args->GetInt("threads", 0);
  for (const absl::Status& s : {iters.status(), batch.status(), seed.status(), threads.status()}) {
    if (!s.ok()) return Fail("train-guard", s);
  }
  if (*iters < 1 || *batch < 1) {
    return Fail("train-guard", absl::InvalidArgumentError("--iters and --batch must be at least 1"));
  }
  o.iterations = *iters, o.batch = *batch, o.seed = *seed;
  model::SetComputeThreads(*threads);
  absl::StatusOr<model::ContentGuardAccuracy> acc = model::TrainContentGuard(o);
  if (!acc.ok()) return Fail("train-guard", acc.status());
  absl::PrintF(
      "held-out clips: %d\ncontent accuracy: %.3f\nstyle accuracy: %.3f\n"
      "guard written to %s/guard.pt (enable it with `content_guard = 1` in config.txt)\n",
      acc->clips, acc->content, acc->style, o.model);
  return 0;
}

}  // namespace stylus::tool
