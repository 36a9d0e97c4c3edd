// What a live model's carried state saves (docs/service.md "Live streams"):
// per streamed frame, one step of the causal networks against recomputing
// them over the last 32 frames (what a stream without carried state would
// do), in multiply-adds and in time, measured in the same run through the
// public StyleModel API:
//   - stream step: Push of one frame to a live stream (features, one network
//     step, decoding), post-processing none and full;
//   - window recompute: a whole-clip Transfer of the last 32 frames (the
//     same features and decoding around a 32-frame pass), post-processing
//     none;
//   - batched steps: B streams stepped together (StyleModel::StepStreams,
//     what the server's step batcher runs), per frame: features (Feed), the
//     networks' step, decoding and post-processing full (Collect), for B = 1
//     to 256;
//   - movement from examples (docs/movement.md "Streams"): a stream step,
//     post-processing full, with no takes (the networks alone), with the
//     style clip's take, and with a style library's takes of one style
//     (--library DIR --style-label NAME), as ratios to the networks alone;
//     for a package that gates takes by action (movement_action_gate), the
//     style clip's take with the gate off too.
// usage: live_step_bench [--model DIR] [--frames 600] [--content BVH]
//                        [--library DIR --style-label NAME]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench/bench_support.h"
#include "model/family_registry.h"
#include "model/movement.h"
#include "model/runtime.h"
#include "motion/bvh.h"

namespace stylus::bench {
namespace {

motion::Motion Frames(const motion::Motion& m, int begin, int end) {
  motion::Motion out = m;
  const int c = m.skeleton.num_channels();
  out.num_frames = end - begin;
  out.values.assign(m.values.begin() + static_cast<size_t>(begin) * c,
                    m.values.begin() + static_cast<size_t>(end) * c);
  return out;
}

// Seconds per frame of `stream` pushed one frame at a time, after 32
// frames of warm-up.
double PerFrame(model::FrameStreamer* stream, const motion::Motion& clip, int frames) {
  for (int f = 0; f < 32; ++f) (void)stream->Push(Frames(clip, f, f + 1));
  const Clock::time_point t0 = Clock::now();
  for (int f = 32; f < 32 + frames; ++f) (void)stream->Push(Frames(clip, f, f + 1));
  return Since(t0) / frames;
}

// Per frame of B streams stepped together: Feed, the batched step, Collect.
int BatchedSteps(const model::StyleModel& m, const motion::Motion& clip,
                 const model::StyleCode& style, int frames) {
  std::printf(
      "batched steps (post full), ms per frame: batch, features, network step, "
      "decoding + post, total\n");
  for (const int batch : {1, 4, 16, 64, 256}) {
    std::vector<std::unique_ptr<model::FrameStreamer>> streams;
    std::vector<model::FrameStreamer*> cores;
    for (int b = 0; b < batch; ++b) {
      auto s =
          m.OpenStream({style, clip.skeleton, clip.frame_time, motion::PostProcessMode::kFull});
      if (!s.ok() || !(*s)->batchable()) {
        std::fprintf(stderr, "live_step_bench: the stream does not batch\n");
        return 1;
      }
      cores.push_back((*s)->step_core());
      streams.push_back(*std::move(s));
    }
    const int n = std::max(40, frames * 4 / batch);
    double t[3] = {0, 0, 0};
    for (int f = 0; f < 32 + n; ++f) {
      const motion::Motion one =
          Frames(clip, f % (clip.num_frames - 1), f % (clip.num_frames - 1) + 1);
      const Clock::time_point a = Clock::now();
      for (auto& s : streams) (void)s->Feed(one);
      const Clock::time_point b = Clock::now();
      if (!streams.front()->has_steps()) continue;  // The features' look-ahead.
      if (absl::Status st = m.StepStreams(cores); !st.ok()) {
        std::fprintf(stderr, "live_step_bench: %s\n", st.ToString().c_str());
        return 1;
      }
      const Clock::time_point c = Clock::now();
      for (auto& s : streams) (void)s->Collect();
      if (f < 32) continue;  // Warm-up.
      t[0] += std::chrono::duration<double>(b - a).count();
      t[1] += std::chrono::duration<double>(c - b).count();
      t[2] += Since(c);
    }
    const double k = 1000.0 / (static_cast<double>(n) * batch);
    std::printf("  %3d  %.4f  %.4f  %.4f  %.4f\n", batch, k * t[0], k * t[1], k * t[2],
                k * (t[0] + t[1] + t[2]));
  }
  return 0;
}

// Per frame of one stream (post full), ms: the networks alone, with the
// style clip's take, with the library's takes of `label`; and, when the
// package gates takes by action, the style clip's take on `ungated` (the
// same package with movement_action_gate = 0).
int MovementCost(const model::StyleModel& m, const model::StyleModel* ungated,
                 const motion::Motion& clip, const model::StyleCode& style, int frames,
                 const std::string& library_dir, const std::string& label) {
  std::unique_ptr<model::StyleLibrary> library;
  if (!library_dir.empty()) {
    auto lib = model::StyleLibrary::Load(library_dir);
    if (!lib.ok()) {
      std::fprintf(stderr, "live_step_bench: %s\n", lib.status().ToString().c_str());
      return 1;
    }
    library = *std::move(lib);
    if (auto converted = library->For(m); !converted.ok()) {  // Read once, before timing.
      std::fprintf(stderr, "live_step_bench: %s\n", converted.status().ToString().c_str());
      return 1;
    }
  }
  model::StyleCode alone = style;
  alone.example = nullptr;
  struct Variant {
    const char* name;
    const model::StyleCode* code;
    model::MovementRequest movement;
    const model::StyleModel* model;
  };
  std::vector<Variant> variants = {{"networks alone", &alone, {}, &m},
                                   {"the style clip's take", &style, {}, &m}};
  if (library) variants.push_back({"the library's takes", &alone, {library.get(), label}, &m});
  if (ungated != nullptr) {
    variants.push_back({"the clip's take, no gate", &style, {}, ungated});
  }
  std::printf(
      "movement from examples (post full), ms per frame and ratio to the networks alone:\n");
  double base = 0;
  for (const Variant& v : variants) {
    model::StreamSpec spec{*v.code, clip.skeleton, clip.frame_time, motion::PostProcessMode::kFull};
    spec.movement = v.movement;
    auto s = v.model->OpenStream(spec);
    if (!s.ok()) {
      std::fprintf(stderr, "live_step_bench: %s\n", s.status().ToString().c_str());
      return 1;
    }
    const double ms = 1000 * PerFrame(s->get(), clip, frames);
    if (base == 0) base = ms;
    std::printf("  %-24s %.3f  %.2fx\n", v.name, ms, ms / base);
  }
  return 0;
}

int Main(int argc, char** argv) {
  std::string dir = std::string(STYLUS_SOURCE_DIR) + "/models/live/v3";
  std::string content = std::string(STYLUS_SOURCE_DIR) + "/samples/walk_normal.bvh";
  std::string library, label;
  int frames = 600;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--help")) {
      std::printf(
          "usage: live_step_bench [--model DIR] [--frames 600] [--content BVH]\n"
          "                       [--library DIR --style-label NAME]\n");
      return 0;
    }
    if (i + 1 < argc && !std::strcmp(argv[i], "--model"))
      dir = argv[++i];
    else if (i + 1 < argc && !std::strcmp(argv[i], "--frames"))
      frames = std::atoi(argv[++i]);
    else if (i + 1 < argc && !std::strcmp(argv[i], "--content"))
      content = argv[++i];
    else if (i + 1 < argc && !std::strcmp(argv[i], "--library"))
      library = argv[++i];
    else if (i + 1 < argc && !std::strcmp(argv[i], "--style-label"))
      label = argv[++i];
    else {
      std::fprintf(stderr, "live_step_bench: unknown argument %s (see --help)\n", argv[i]);
      return 2;
    }
  }
  if (const char* core = std::getenv("OPENBLAS_CORETYPE"))
    std::printf("OPENBLAS_CORETYPE=%s (set in the environment)\n", core);
  model::SetComputeThreads(1);
  absl::StatusOr<std::shared_ptr<const model::StyleModel>> m(model::LoadStyleModel(dir));
  if (!m.ok()) {
    std::fprintf(stderr, "live_step_bench: %s\n", m.status().ToString().c_str());
    return 1;
  }
  const model::ModelSummary summary = (*m)->summary();
  if (!summary.live) {
    std::fprintf(stderr, "live_step_bench: %s is not a live package\n", dir.c_str());
    return 1;
  }
  absl::StatusOr<motion::Motion> read = motion::ReadBvhFile(content);
  if (!read.ok()) {
    std::fprintf(stderr, "live_step_bench: %s\n", read.status().ToString().c_str());
    return 1;
  }
  motion::Motion clip = *std::move(read);
  while (clip.num_frames < frames + 32) {
    clip.values.insert(clip.values.end(), clip.values.begin(), clip.values.end());
    clip.num_frames *= 2;
  }
  const model::StyleCode style = *(*m)->EncodeStyle(
      *motion::ReadBvhFile(std::string(STYLUS_SOURCE_DIR) + "/samples/walk_old.bvh"));
  std::printf("model %s: %lld multiply-adds per step; a 32-frame recompute: %lld (x32)\n",
              dir.c_str(), static_cast<long long>(summary.step_macs),
              static_cast<long long>(32 * summary.step_macs));
  double per_frame[2] = {0, 0};
  for (const auto post : {motion::PostProcessMode::kNone, motion::PostProcessMode::kFull}) {
    auto s = (*m)->OpenStream({style, clip.skeleton, clip.frame_time, post});
    if (!s.ok()) {
      std::fprintf(stderr, "live_step_bench: %s\n", s.status().ToString().c_str());
      return 1;
    }
    per_frame[post == motion::PostProcessMode::kFull] = PerFrame(s->get(), clip, frames);
  }
  const int reps = std::max(20, frames / 10);
  const Clock::time_point t1 = Clock::now();
  for (int r = 0; r < reps; ++r) {
    (void)(*m)->Transfer(Frames(clip, r, r + 32), style, motion::PostProcessMode::kNone);
  }
  const double window = Since(t1) / reps;
  std::printf("stream step, post none: %.3f ms per frame\n", 1000 * per_frame[0]);
  std::printf("stream step, post full: %.3f ms per frame\n", 1000 * per_frame[1]);
  std::printf("32-frame window recompute, post none: %.3f ms per frame; ratio to the step %.1fx\n",
              1000 * window, window / per_frame[0]);
  // A package that gates takes by action reads the style clip's action.
  std::shared_ptr<const model::StyleModel> ungated;
  if (!style.example_actions.empty()) {
    absl::StatusOr<std::unique_ptr<model::StyleModel>> u =
        model::LoadStyleModel(dir, {{"movement_action_gate", "0"}});
    if (!u.ok()) {
      std::fprintf(stderr, "live_step_bench: %s\n", u.status().ToString().c_str());
      return 1;
    }
    ungated = *std::move(u);
  }
  if (const int r = MovementCost(**m, ungated.get(), clip, style, frames, library, label); r != 0) {
    return r;
  }
  return BatchedSteps(**m, clip, style, frames);
}

}  // namespace
}  // namespace stylus::bench

int main(int argc, char** argv) { return stylus::bench::Main(argc, argv); }
