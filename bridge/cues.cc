#include "bridge/cues.h"

#include <cmath>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace stylus::bridge {

absl::StatusOr<std::vector<Cue>> ParseCues(absl::string_view text, absl::string_view source) {
  std::vector<Cue> cues;
  int number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++number;
    line = absl::StripAsciiWhitespace(line.substr(0, line.find('#')));
    if (line.empty()) continue;
    auto fail = [&](const std::string& what) {
      return absl::InvalidArgumentError(absl::StrCat(source, ":", number, ": ", what));
    };
    std::vector<absl::string_view> f = absl::StrSplit(line, absl::MaxSplits(absl::ByAnyChar(" \t"), 2),
                                                      absl::SkipEmpty());
    Cue cue;
    if (f.size() != 3 || !absl::SimpleAtod(f[0], &cue.seconds) || !std::isfinite(cue.seconds) ||
        cue.seconds < 0) {
      return fail("expected 'SECONDS style NAME-OR-CLIP' or 'SECONDS strength K'");
    }
    if (!cues.empty() && cue.seconds < cues.back().seconds) {
      return fail(absl::StrCat("cue at ", f[0], " s comes before the one above it"));
    }
    const std::string what(f[1]);
    if (what == "style") {
      cue.style = std::string(absl::StripAsciiWhitespace(f[2]));
    } else if (what == "strength") {
      cue.strength = true;
      if (!absl::SimpleAtod(f[2], &cue.value) || !(cue.value >= 0 && cue.value <= 1)) {
        return fail(absl::StrCat("strength wants a number from 0 to 1, not '", f[2], "'"));
      }
    } else {
      return fail(absl::StrCat("'", what, "': a cue changes the style or the strength"));
    }
    cues.push_back(std::move(cue));
  }
  return cues;
}

}  // namespace stylus::bridge
