// BVH and feature throughput over a directory of clips (default: Bandai
// dataset-2). Prints frames/s for parsing, writing and feature extraction, each
// also as a ratio to a baseline measured in the same run: a plain scan that
// reads every byte of the same text and counts its numbers (the floor any
// parser has to pay). Best of --reps runs. Usage:
//   bvh_bench [DIR] [--reps N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/features.h"

namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point a) {
  return std::chrono::duration<double>(Clock::now() - a).count();
}

// Baseline: count whitespace-separated tokens (touches every byte once).
size_t CountTokens(const std::string& s) {
  size_t n = 0;
  bool in = false;
  for (char c : s) {
    const bool space = c == ' ' || c == '\n' || c == '\t' || c == '\r';
    n += (!space && !in);
    in = !space;
  }
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  std::string dir;
  int reps = 3;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      std::printf("usage: bvh_bench [DIR] [--reps N]\n  DIR defaults to the Bandai dataset-2.\n");
      return 0;
    }
    if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) {
      reps = std::max(1, std::atoi(argv[++i]));
    } else {
      dir = argv[i];
    }
  }
  if (dir.empty()) {
    std::optional<std::string> data = stylus::motion::FindBandaiData(STYLUS_SOURCE_DIR);
    if (!data) {
      std::fprintf(stderr, "bvh_bench: no DIR given and no Bandai data found\n");
      return 1;
    }
    dir = *data + "/dataset-2";
  }
  std::vector<std::string> texts;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    if (e.path().extension() != ".bvh") continue;
    std::ifstream in(e.path(), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    texts.push_back(ss.str());
  }
  if (texts.empty()) {
    std::fprintf(stderr, "bvh_bench: no .bvh files under %s\n", dir.c_str());
    return 1;
  }
  size_t bytes = 0;
  for (const auto& t : texts) bytes += t.size();

  double scan = 1e9, parse = 1e9, write = 1e9, features = 1e9;
  long frames = 0;
  size_t tokens = 0;
  for (int r = 0; r < reps; ++r) {
    auto t0 = Clock::now();
    tokens = 0;
    for (const auto& t : texts) tokens += CountTokens(t);
    scan = std::min(scan, Seconds(t0));

    std::vector<stylus::motion::Motion> motions;
    t0 = Clock::now();
    for (const auto& t : texts) motions.push_back(*stylus::motion::ParseBvh(t, "bench"));
    parse = std::min(parse, Seconds(t0));

    frames = 0;
    size_t out = 0;
    t0 = Clock::now();
    for (const auto& m : motions) {
      out += stylus::motion::FormatBvh(m).size();
      frames += m.num_frames;
    }
    write = std::min(write, Seconds(t0));

    const auto roles = *stylus::motion::FindHumanoidRoles(motions[0].skeleton);
    t0 = Clock::now();
    for (const auto& m : motions) out += stylus::motion::ExtractFeatures(m, roles)->values.size();
    features = std::min(features, Seconds(t0));
    if (out == 0) std::printf("(nothing written)\n");
  }
  std::printf("clips %zu, frames %ld, %.1f MB, %zu tokens, best of %d\n", texts.size(), frames,
              bytes / 1e6, tokens, reps);
  std::printf("%-22s %12s %14s %10s\n", "stage", "seconds", "frames/s", "x baseline");
  auto row = [&](const char* name, double s) {
    std::printf("%-22s %12.3f %14.0f %10.2f\n", name, s, frames / s, s / scan);
  };
  row("baseline token scan", scan);
  row("parse (ParseBvh)", parse);
  row("write (FormatBvh)", write);
  row("features (Extract)", features);
  return 0;
}
