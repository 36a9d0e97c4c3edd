#include "motion/normalization.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "motion/files.h"

namespace stylus::motion {

absl::StatusOr<NormStats> NormStats::Compute(const std::vector<const FeatureClip*>& clips,
                                             std::vector<std::string> names, float min_std) {
  if (clips.empty()) return absl::InvalidArgumentError("no clips to compute statistics from");
  const int dim = clips[0]->dim;
  if (!names.empty() && static_cast<int>(names.size()) != dim) {
    return absl::InvalidArgumentError("channel names do not match the feature width");
  }
  std::vector<double> sum(dim, 0), sum_sq(dim, 0);
  double count = 0;
  for (const FeatureClip* c : clips) {
    if (c->dim != dim) {
      return absl::InvalidArgumentError(
          absl::StrCat("clip of width ", c->dim, " among clips of width ", dim));
    }
    for (int f = 0; f < c->frames; ++f) {
      const float* r = c->row(f);
      for (int k = 0; k < dim; ++k) sum[k] += r[k];
    }
    count += c->frames;
  }
  if (count == 0) return absl::InvalidArgumentError("clips have no frames");
  NormStats s;
  s.mean.resize(dim);
  s.std.resize(dim);
  for (int k = 0; k < dim; ++k) s.mean[k] = static_cast<float>(sum[k] / count);
  for (const FeatureClip* c : clips) {  // Two passes: no catastrophic cancellation.
    for (int f = 0; f < c->frames; ++f) {
      const float* r = c->row(f);
      for (int k = 0; k < dim; ++k) {
        const double d = r[k] - s.mean[k];
        sum_sq[k] += d * d;
      }
    }
  }
  for (int k = 0; k < dim; ++k) {
    const double sd = std::sqrt(sum_sq[k] / count);
    s.std[k] = sd < min_std ? 1.f : static_cast<float>(sd);
  }
  s.names = names.empty() ? std::vector<std::string>(dim, "") : std::move(names);
  return s;
}

void NormStats::Normalize(FeatureClip* clip) const {
  for (int f = 0; f < clip->frames; ++f) Normalize(clip->row(f));
}

void NormStats::Denormalize(FeatureClip* clip) const {
  for (int f = 0; f < clip->frames; ++f) Denormalize(clip->row(f));
}

void NormStats::Normalize(float* r) const {
  for (int k = 0; k < dim(); ++k) r[k] = (r[k] - mean[k]) / std[k];
}

void NormStats::Denormalize(float* r) const {
  for (int k = 0; k < dim(); ++k) r[k] = r[k] * std[k] + mean[k];
}

namespace {
std::string Shortest(float v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, ec == std::errc() ? end : buf);
}
}  // namespace

std::string NormStats::Serialize() const {
  std::string out = absl::StrCat("stylus-norm 1 ", dim(), "\n");
  for (int k = 0; k < dim(); ++k) {
    absl::StrAppend(&out, names[k].empty() ? "-" : names[k], " ", Shortest(mean[k]), " ",
                    Shortest(std[k]), "\n");
  }
  return out;
}

absl::StatusOr<NormStats> NormStats::Parse(const std::string& text, const std::string& source) {
  std::vector<absl::string_view> lines = absl::StrSplit(text, '\n', absl::SkipEmpty());
  auto error = [&](int line, absl::string_view what) {
    return absl::InvalidArgumentError(absl::StrCat(source, ":", line, ": ", what));
  };
  if (lines.empty()) return error(1, "empty normalization file");
  std::vector<absl::string_view> head = absl::StrSplit(lines[0], ' ', absl::SkipEmpty());
  int dim = 0;
  if (head.size() != 3 || head[0] != "stylus-norm" || head[1] != "1" ||
      !absl::SimpleAtoi(head[2], &dim) || dim <= 0 || dim > 1000000) {
    return error(1, "expected header 'stylus-norm 1 <channels>'");
  }
  if (static_cast<int>(lines.size()) != dim + 1) {
    return error(static_cast<int>(lines.size()),
                 absl::StrCat("expected ", dim, " channel lines, found ", lines.size() - 1));
  }
  NormStats s;
  for (int k = 0; k < dim; ++k) {
    std::vector<absl::string_view> f = absl::StrSplit(lines[k + 1], ' ', absl::SkipEmpty());
    float mean = 0, sd = 0;
    if (f.size() != 3 || !absl::SimpleAtof(f[1], &mean) || !absl::SimpleAtof(f[2], &sd) ||
        !std::isfinite(mean) || !std::isfinite(sd) || sd <= 0) {
      return error(k + 2, "expected 'name mean std' with finite numbers and std > 0");
    }
    s.names.emplace_back(f[0] == "-" ? "" : std::string(f[0]));
    s.mean.push_back(mean);
    s.std.push_back(sd);
  }
  return s;
}

absl::Status NormStats::Save(const std::string& path) const {
  return WriteFileAtomically(path, Serialize());
}

absl::StatusOr<NormStats> NormStats::Load(const std::string& path) {
  std::ifstream f(path);
  if (!f) return absl::NotFoundError(absl::StrCat(path, ": cannot open file"));
  std::stringstream ss;
  ss << f.rdbuf();
  return Parse(ss.str(), path);
}

}  // namespace stylus::motion
