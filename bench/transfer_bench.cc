// Transfer speed of a model package: seconds per 1000 frames of content with
// one compute thread and with two, each also as a ratio to the baseline measured
// in the same run: feature extraction plus motion reconstruction of the same
// clip without the network (the part of a transfer that is not inference).
// A package with movement from examples is also timed with the network's
// movement only (docs/movement.md): what taking the movement from the style
// clip costs. Any family. Usage: transfer_bench [MODEL_DIR] [--frames N] [--reps N] [--kc N]
// (--kc: a cyclic model's inference-time kinematic optimization steps).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>

#include "model/family_registry.h"
#include "model/package.h"
#include "model/runtime.h"
#include "model/style_model.h"
#include "motion/features.h"
#include "motion/synth.h"

namespace {
using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}
}  // namespace

int main(int argc, char** argv) {
  const std::string models = std::string(STYLUS_SOURCE_DIR) + "/models";
  std::string dir = models + "/" + stylus::model::ReadDefaultPackage(models).value();
  int frames = 1000, reps = 5, kc = -1;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--help")) {
      std::printf("usage: transfer_bench [MODEL_DIR] [--frames N] [--reps N] [--kc N]\n");
      return 0;
    }
    if (!std::strcmp(argv[i], "--frames") && i + 1 < argc) {
      frames = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--kc") && i + 1 < argc) {
      kc = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) {
      reps = std::max(1, std::atoi(argv[++i]));
    } else {
      dir = argv[i];
    }
  }
  stylus::model::ConfigOverrides overrides;
  if (kc >= 0) overrides.emplace_back("kc_iters", std::to_string(kc));
  absl::StatusOr<std::unique_ptr<stylus::model::StyleModel>> model =
      stylus::model::LoadStyleModel(dir, overrides);
  if (!model.ok()) {
    std::fprintf(stderr, "transfer_bench: %s\n", std::string(model.status().message()).c_str());
    return 1;
  }
  const auto content = *stylus::motion::Synthesize(
      *stylus::motion::ParseSynthStyle("normal,frames=" + std::to_string(frames)));
  const auto style_clip =
      *stylus::motion::Synthesize(*stylus::motion::ParseSynthStyle("old,frames=120"));
  const auto& roles = (*model)->data().roles;
  std::printf("model %s (%s%s), content %d frames, best of %d\n", dir.c_str(),
              (*model)->summary().family.c_str(),
              kc >= 0 ? (", kc " + std::to_string(kc)).c_str() : "", frames, reps);
  std::printf("%-34s %10s %14s %10s\n", "stage", "threads", "s/1000 frames", "x baseline");
  stylus::model::TransferNote note;
  stylus::model::MovementNote movement;
  const bool moves = (*model)->moves_from_examples();
  for (int threads : {1, 2}) {
    stylus::model::SetComputeThreads(threads);
    double base = 1e9, transfer = 1e9, network_only = 1e9;
    for (int r = 0; r < reps; ++r) {
      auto t0 = Clock::now();
      const auto f = *stylus::motion::ExtractFeatures(content, roles);
      const auto m =
          *stylus::motion::MotionFromFeatures(f, content.skeleton, roles, content.frame_time);
      base = std::min(base, Since(t0));
      t0 = Clock::now();
      const auto code = *(*model)->EncodeStyle(style_clip);
      const stylus::model::TransferResult result =
          *(*model)->Transfer(content, code, stylus::motion::PostProcessMode::kFull);
      note = result.note;
      movement = result.movement;
      const stylus::motion::Motion& out = result.motion;
      transfer = std::min(transfer, Since(t0));
      if (out.num_frames != m.num_frames) return 1;
      if (moves) {
        t0 = Clock::now();
        stylus::model::TransferOptions options(stylus::motion::PostProcessMode::kFull);
        options.movement_from_examples = false;
        const auto code2 = *(*model)->EncodeStyle(style_clip);
        if (!(*model)->Transfer(content, code2, options).ok()) return 1;
        network_only = std::min(network_only, Since(t0));
      }
    }
    const double k = 1000.0 / frames;
    std::printf("%-34s %10d %14.4f %10.2f\n", "baseline (features + rebuild)", threads, base * k,
                1.0);
    std::printf("%-34s %10d %14.4f %10.2f\n", "transfer (encode style + transfer)", threads,
                transfer * k, transfer / base);
    if (moves) {
      std::printf("%-34s %10d %14.4f %10.2f   (with movement: %.2fx)\n",
                  "transfer, network's movement", threads, network_only * k, network_only / base,
                  transfer / network_only);
    }
  }
  if (moves) {
    std::printf("movement: %s\n", movement.applied
                                      ? (movement.kind + " from the " + movement.example).c_str()
                                      : ("the network's: " + movement.reason).c_str());
  }
  // A package's content guard makes a transfer again in each residual form
  // until its action reads right: say which form the timed transfer was.
  if (note.guarded) {
    if (note.backed_off) {
      std::printf("content guard: residual form at strength %g%s\n", note.residual_strength,
                  note.last_form ? " (the last form)" : "");
    } else {
      std::printf("content guard: the configured form\n");
    }
  }
  return 0;
}
