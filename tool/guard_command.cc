// train-guard: the content guard of a package (either family).
#include <cstdio>

#include "absl/strings/str_format.h"
#include "model/content_guard.h"
#include "model/runtime.h"
#include "tool/cli_support.h"
#include "train/guard_trainer.h"

namespace stylus::tool {

int TrainGuard(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool train-guard --model DIR --data DIR... [--iters 3000]\n"
      "         [--batch 32] [--guards 3] [--seed S] [--threads N]\n\n"
      "Trains the content guard of the package DIR (either family): --guards\n"
      "classifiers of the action (seeds S, S+1, ...; their probabilities are\n"
      "averaged), on the labelled training split of the --data directories in\n"
      "the package's own features, and writes guard_K.pt and guard.txt into DIR.\n"
      "Prints the clip-level accuracy on the held-out split.\n"
      "The package uses it when its config.txt says `content_guard = 1`: a\n"
      "whole-clip transfer the guard reads as another action than its content\n"
      "clip is made again with a weaker style at each of `guard_strengths`\n"
      "(default 1,0.7,0.4,0.2), giving up style until the action reads right\n"
      "(docs/notes/contrastive.md; for cyclic packages docs/notes/cyclic.md).\n";
  int code = 0;
  auto args = ParseOrExit("train-guard", argv,
                          {{"model", "data", "iters", "batch", "seed", "threads", "guards"}, {}},
                          kHelp, &code);
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
                      threads = args->GetInt("threads", 0),
                      guards = args->GetInt("guards", o.guards);
  for (const absl::Status& s :
       {iters.status(), batch.status(), seed.status(), threads.status(), guards.status()}) {
    if (!s.ok()) return Fail("train-guard", s);
  }
  if (*iters < 1 || *batch < 1) {
    return Fail("train-guard",
                absl::InvalidArgumentError("--iters and --batch must be at least 1"));
  }
  o.iterations = *iters, o.batch = *batch, o.seed = *seed, o.guards = *guards;
  model::SetComputeThreads(*threads);
  absl::StatusOr<model::ContentGuardAccuracy> acc = model::TrainContentGuard(o);
  if (!acc.ok()) return Fail("train-guard", acc.status());
  if (acc->clips > 0) {
    std::string each;
    for (double a : acc->each) absl::StrAppendFormat(&each, "%s%.3f", each.empty() ? "" : ", ", a);
    absl::PrintF("held-out clips: %d\ncontent accuracy: %.3f (each guard: %s)\n", acc->clips,
                 acc->content, each);
  } else {
    absl::PrintF(
        "held-out clips: 0 (single files have no held-out split; accuracy not measured)\n");
  }
  absl::PrintF("%d guards written to %s (enable them with `content_guard = 1` in config.txt)\n",
               o.guards, o.model);
  return 0;
}

}  // namespace stylus::tool
