#include "model/contrastive_config.h"

#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace stylus::model {

std::string ContrastiveConfig::Serialize() const {
  std::string s;
  auto put = [&](const char* k, const std::string& v) { absl::StrAppend(&s, k, " = ", v, "\n"); };
  put("family", family);
  put("window", absl::StrCat(window));
  put("hop", absl::StrCat(hop));
  put("dim", absl::StrCat(dim));
  put("channels", absl::StrCat(channels));
  put("res_kernel", absl::StrCat(res_kernel));
  put("alpha", absl::StrCat(alpha));
  put("beta", absl::StrCat(beta));
  put("gamma", absl::StrCat(gamma));
  put("margin", absl::StrCat(margin));
  put("temperature", absl::StrCat(temperature));
  put("use_nce", use_nce ? "1" : "0");
  put("use_tri", use_tri ? "1" : "0");
  put("cross_view", cross_view ? "1" : "0");
  put("local_style", local_style ? "1" : "0");
  put("keep_amplitude", keep_amplitude ? "1" : "0");
  if (centred_style) put("centred_style", "1");
  if (content_weight > 0) put("content_weight", absl::StrCat(content_weight));
  put("batch", absl::StrCat(batch));
  put("lr", absl::StrCat(lr));
  put("iterations", absl::StrCat(iterations));
  put("seed", absl::StrCat(seed));
  put("trained_iterations", absl::StrCat(trained_iterations));
  put("data", data);
  put("commit", commit);
  return s;
}

absl::StatusOr<ContrastiveConfig> ContrastiveConfig::Parse(const std::string& text,
                                                           const std::string& source) {
  ContrastiveConfig c;
  int line_no = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_no;
    line = absl::StripAsciiWhitespace(line);
    if (line.empty() || line[0] == '#') continue;
    const size_t eq = line.find('=');
    auto error = [&](absl::string_view what) {
      return absl::InvalidArgumentError(absl::StrCat(source, ":", line_no, ": ", what));
    };
    if (eq == absl::string_view::npos) return error("expected 'key = value'");
    const std::string key(absl::StripAsciiWhitespace(line.substr(0, eq)));
    const std::string value(absl::StripAsciiWhitespace(line.substr(eq + 1)));
    auto to_int = [&](int* out, int lo, int hi) -> absl::Status {
      if (!absl::SimpleAtoi(value, out) || *out < lo || *out > hi) {
        return error(absl::StrCat(key, " must be a whole number in [", lo, ", ", hi, "]"));
      }
      return absl::OkStatus();
    };
    auto to_double = [&](double* out, double lo, double hi) -> absl::Status {
      if (!absl::SimpleAtod(value, out) || !(*out >= lo && *out <= hi)) {
        return error(absl::StrCat(key, " must be a number in [", lo, ", ", hi, "]"));
      }
      return absl::OkStatus();
    };
    absl::Status s;
    if (key == "family") {
      if (value != "contrastive")
        return error("family must be 'contrastive', found '" + value + "'");
    } else if (key == "window") {
      s = to_int(&c.window, 4, 4096);
      if (s.ok() && c.window % 2) s = error("window must be even");
    } else if (key == "hop") {
      s = to_int(&c.hop, 1, 4096);
    } else if (key == "dim") {
      s = to_int(&c.dim, 1, 100000);
    } else if (key == "channels") {
      s = to_int(&c.channels, 1, 4096);
    } else if (key == "res_kernel") {
      s = to_int(&c.res_kernel, 1, 31);
      if (s.ok() && c.res_kernel % 2 == 0) s = error("res_kernel must be odd");
    } else if (key == "alpha") {
      s = to_double(&c.alpha, 0, 1e6);
    } else if (key == "beta") {
      s = to_double(&c.beta, 0, 1e6);
    } else if (key == "gamma") {
      s = to_double(&c.gamma, 0, 1e6);
    } else if (key == "content_weight") {
      s = to_double(&c.content_weight, 0, 1e6);
    } else if (key == "margin") {
      s = to_double(&c.margin, 0, 1e6);
    } else if (key == "temperature") {
      s = to_double(&c.temperature, 1e-6, 1e6);
    } else if (key == "use_nce" || key == "use_tri" || key == "cross_view" ||
               key == "local_style" || key == "keep_amplitude" || key == "centred_style") {
      if (value != "0" && value != "1") return error(key + " must be 0 or 1");
      bool* flag = key == "use_nce"       ? &c.use_nce
                   : key == "use_tri"     ? &c.use_tri
                   : key == "cross_view"  ? &c.cross_view
                   : key == "local_style" ? &c.local_style
                   : key == "centred_style" ? &c.centred_style
                                          : &c.keep_amplitude;
      *flag = value == "1";
    } else if (key == "batch") {
      s = to_int(&c.batch, 1, 1 << 20);
    } else if (key == "lr") {
      s = to_double(&c.lr, 0, 10);
    } else if (key == "iterations") {
      s = to_int(&c.iterations, 0, 1 << 30);
    } else if (key == "trained_iterations") {
      s = to_int(&c.trained_iterations, 0, 1 << 30);
    } else if (key == "seed") {
      if (!absl::SimpleAtoi(value, &c.seed)) s = error("seed must be a whole number");
    } else if (key == "data") {
      c.data = value;
    } else if (key == "commit") {
      c.commit = value;
    } else {
      return error("unknown key '" + key + "'");
    }
    if (!s.ok()) return s;
  }
  if (c.dim <= 0) return absl::InvalidArgumentError(source + ": missing 'dim'");
  return c;
}

}  // namespace stylus::model
