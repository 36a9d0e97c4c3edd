#include "model/style_model.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace stylus::model {

absl::Status CheckStyleMix(const std::vector<StyleCode>& styles, const StyleWeights& weights,
                           int frames, int code_size) {
  if (styles.empty()) return absl::InvalidArgumentError("no style given");
  for (const StyleCode& s : styles) {
    if (static_cast<int>(s.values.size()) != code_size) {
      return absl::InvalidArgumentError(absl::StrCat(
          "style code has ", s.values.size(), " values; this model's have ", code_size));
    }
  }
  const bool per_frame = !weights.per_frame.empty();
  if (per_frame && static_cast<int>(weights.per_frame.size()) != frames) {
    return absl::InvalidArgumentError(absl::StrCat("weight schedule has ", weights.per_frame.size(),
                                                   " rows; the content clip has ", frames,
                                                   " frames"));
  }
  for (const auto& row :
       per_frame ? weights.per_frame : std::vector<std::vector<double>>{weights.fixed}) {
    if (row.size() != styles.size()) {
      return absl::InvalidArgumentError(
          absl::StrCat("got ", row.size(), " weights for ", styles.size(), " styles"));
    }
    for (double w : row) {
      if (!std::isfinite(w)) return absl::InvalidArgumentError("style weights must be finite");
    }
  }
  return absl::OkStatus();
}

bool IsServedFamily(const std::string& family) {
  return family == "contrastive" || family == "cyclic";
}

StyleCode MixStyles(const std::vector<StyleCode>& styles, const std::vector<double>& mix) {
  StyleCode out;
  out.values.assign(styles[0].values.size(), 0.f);
  for (size_t c = 0; c < out.values.size(); ++c) {
    double v = 0;
    for (size_t k = 0; k < styles.size(); ++k) v += mix[k] * styles[k].values[c];
    out.values[c] = static_cast<float>(v);
  }
  return out;
}

}  // namespace stylus::model
