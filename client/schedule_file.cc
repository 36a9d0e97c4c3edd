#include "client/schedule_file.h"

#include <cmath>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace stylus {

absl::StatusOr<std::vector<std::vector<double>>> ParseSchedule(absl::string_view text,
                                                               absl::string_view source,
                                                               int num_styles, int num_frames) {
  std::vector<std::pair<int, std::vector<double>>> keys;
  int line_number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    line = line.substr(0, line.find('#'));
    std::vector<absl::string_view> fields =
        absl::StrSplit(line, absl::ByAnyChar(" \t,\r"), absl::SkipEmpty());
    if (fields.empty()) continue;
    auto fail = [&](const std::string& what) {
      return absl::InvalidArgumentError(absl::StrCat(source, ":", line_number, ": ", what));
    };
    int frame;
    if (!absl::SimpleAtoi(fields[0], &frame) || frame < 0) {
      return fail(absl::StrCat("expected a frame number >= 0 first, not '", fields[0], "'"));
    }
    if (!keys.empty() && frame <= keys.back().first) {
      return fail(absl::StrCat("frame ", frame, " after frame ", keys.back().first,
                               ": keyframes go in increasing order"));
    }
    if (static_cast<int>(fields.size()) != num_styles + 1) {
      return fail(absl::StrCat(fields.size() - 1, " weights for ", num_styles,
                               " styles (one per --style, in their order)"));
    }
    std::vector<double> weights;
    for (size_t i = 1; i < fields.size(); ++i) {
      double w;
      if (!absl::SimpleAtod(fields[i], &w) || !std::isfinite(w)) {
        return fail(absl::StrCat("'", fields[i], "' is not a number"));
      }
      weights.push_back(w);
    }
    keys.push_back({frame, std::move(weights)});
  }
  if (keys.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(source, ": no keyframes (lines like '0 1 0' then '60 0 1')"));
  }
  std::vector<std::vector<double>> rows(num_frames);
  size_t k = 0;
  for (int f = 0; f < num_frames; ++f) {
    while (k + 1 < keys.size() && keys[k + 1].first <= f) ++k;
    if (f <= keys[k].first || k + 1 == keys.size()) {
      rows[f] = keys[k].second;
      continue;
    }
    const auto& [f0, w0] = keys[k];
    const auto& [f1, w1] = keys[k + 1];
    const double t = static_cast<double>(f - f0) / (f1 - f0);
    rows[f].resize(num_styles);
    for (int s = 0; s < num_styles; ++s) rows[f][s] = w0[s] + t * (w1[s] - w0[s]);
  }
  return rows;
}

}  // namespace stylus
