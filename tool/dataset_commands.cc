// dataset-stats.
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>

#include "absl/strings/str_format.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/features.h"
#include "motion/humanoid.h"
#include "motion/normalization.h"
#include "tool/cli_support.h"

namespace stylus::tool {

int DatasetStats(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool dataset-stats DIR... [--norm-out FILE] [--seed N] [--held-out]\n\n"
      "Indexes the labelled clips (dataset-N_content_style_take.bvh) under each DIR,\n"
      "parses every one, and prints clip, frame and duration totals, counts per\n"
      "content and per style (train/test split by take, 10% held out), and the BVH\n"
      "parse speed. With --norm-out, also computes per-channel feature mean/std over\n"
      "the training split and writes them to FILE. Exits 1 if any clip fails to parse.\n"
      "--held-out prints only the held-out clips' paths, one per line (what\n"
      "stylus-tool eval pairs from), and reads nothing else.\n";
  int code = 0;
  auto args = ParseOrExit("dataset-stats", argv, {{"norm-out", "seed"}, {"held-out"}}, kHelp, &code);
  if (!args) return code;
  if (args->positional.empty()) {
    std::fprintf(stderr, "stylus-tool dataset-stats: expected at least one DIR\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<int> seed = args->GetInt("seed", 0);
  if (!seed.ok()) return Fail("dataset-stats", seed.status());
  motion::SplitOptions split;
  split.seed = static_cast<uint64_t>(*seed);
  absl::StatusOr<motion::DatasetIndex> index = motion::IndexDataset(args->positional, split);
  if (!index.ok()) return Fail("dataset-stats", index.status());
  for (const std::string& s : index->skipped) std::fprintf(stderr, "skipped %s\n", s.c_str());
  if (args->switches.count("held-out") > 0) {
    for (const motion::ClipEntry* clip : index->Split(true)) absl::PrintF("%s\n", clip->path);
    return 0;
  }

  struct Count {
    int train = 0, test = 0;
    long frames = 0;
  };
  std::map<std::string, Count> by_content, by_style;
  long total_frames = 0;
  double total_seconds = 0, parse_seconds = 0;
  int failures = 0;
  const bool want_norm = args->Has("norm-out");
  std::vector<std::unique_ptr<motion::FeatureClip>> features;
  const size_t n = index->clips.size();
  for (size_t i = 0; i < n; ++i) {
    const motion::ClipEntry& clip = index->clips[i];
    const auto t0 = std::chrono::steady_clock::now();
    absl::StatusOr<motion::Motion> m = motion::ReadBvhFile(clip.path);
    parse_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!m.ok()) {
      std::fprintf(stderr, "error: %s\n", std::string(m.status().message()).c_str());
      ++failures;
      continue;
    }
    total_frames += m->num_frames;
    total_seconds += m->num_frames * m->frame_time;
    for (Count* c : {&by_content[clip.label.content], &by_style[clip.label.style]}) {
      (clip.test ? c->test : c->train)++;
      c->frames += m->num_frames;
    }
    if (want_norm && !clip.test) {
      absl::StatusOr<motion::HumanoidRoles> roles = motion::FindHumanoidRoles(m->skeleton);
      absl::StatusOr<motion::FeatureClip> f =
          roles.ok() ? motion::ExtractFeatures(*m, *roles)
                     : absl::StatusOr<motion::FeatureClip>(roles.status());
      if (!f.ok()) {
        std::fprintf(stderr, "error: %s: %s\n", clip.path.c_str(),
                     std::string(f.status().message()).c_str());
        ++failures;
        continue;
      }
      features.push_back(std::make_unique<motion::FeatureClip>(*std::move(f)));
    }
    if ((i + 1) % 100 == 0 || i + 1 == n) std::fprintf(stderr, "\rread %zu/%zu clips", i + 1, n);
  }
  std::fprintf(stderr, "\n");
  absl::PrintF("clips: %d (train %d, test %d)\n", n, index->Split(false).size(),
               index->Split(true).size());
  absl::PrintF("frames: %d  duration: %.1f min\n", total_frames, total_seconds / 60);
  absl::PrintF("parse: %.2f s, %.0f frames/s\n", parse_seconds,
               total_frames / std::max(parse_seconds, 1e-9));
  for (const auto& [title, table] :
       {std::pair{"content", &by_content}, std::pair{"style", &by_style}}) {
    absl::PrintF("\n%-20s %6s %6s %8s\n", title, "train", "test", "frames");
    for (const auto& [name, c] : *table)
      absl::PrintF("%-20s %6d %6d %8d\n", name, c.train, c.test, c.frames);
  }
  if (want_norm && !features.empty()) {
    std::vector<const motion::FeatureClip*> ptrs;
    for (const auto& f : features) ptrs.push_back(f.get());
    absl::StatusOr<motion::NormStats> stats = motion::NormStats::Compute(ptrs);
    if (!stats.ok()) return Fail("dataset-stats", stats.status());
    if (absl::Status s = stats->Save(args->Get("norm-out")); !s.ok())
      return Fail("dataset-stats", s);
    absl::PrintF("\nwrote normalization statistics of %d channels to %s\n", stats->dim(),
                 args->Get("norm-out"));
  }
  if (failures > 0) {
    std::fprintf(stderr, "stylus-tool dataset-stats: %d clip(s) failed\n", failures);
    return 1;
  }
  return 0;
}

}  // namespace stylus::tool
