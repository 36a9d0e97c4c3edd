// synth.
#include <cstdio>

#include "absl/strings/str_format.h"
#include "motion/bvh.h"
#include "motion/synth.h"
#include "tool/cli_support.h"

namespace stylus::tool {

int Synth(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool synth --style KNOBS -o FILE\n\n"
      "Synthesizes a walk or run on the Bandai skeleton and writes it as BVH.\n"
      "KNOBS is PRESET[,key=value...] or key=value,... e.g. 'old', 'run,speed=400',\n"
      "'lean=12,arm_swing=5,frames=300'.\n"
      "Presets: normal old tired proud happy sneaky run.\n"
      "Keys: gait (walk|run), speed (cm/s), stride (cm per cycle), lean, head_drop,\n"
      "arm_swing, elbow, arm_out (degrees), bounce, foot_lift (cm), crouch (fraction\n"
      "of leg length), sway (cm), turn (deg/s), frames, fps.\n";
  int code = 0;
  auto args = ParseOrExit("synth", argv, {{"style", "out"}, {}}, kHelp, &code);
  if (!args) return code;
  if (!args->Has("out") || !args->positional.empty()) {
    std::fprintf(stderr, "stylus-tool synth: -o FILE is required\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<motion::SynthStyle> style = motion::ParseSynthStyle(args->Get("style", "normal"));
  if (!style.ok()) return Fail("synth", style.status());
  absl::StatusOr<motion::Motion> m = motion::Synthesize(*style);
  if (!m.ok()) return Fail("synth", m.status());
  if (absl::Status s = motion::WriteBvhFile(*m, args->Get("out")); !s.ok()) return Fail("synth", s);
  absl::PrintF("wrote %s: %d frames at %g fps\n", args->Get("out"), m->num_frames, m->fps());
  return 0;
}

}  // namespace stylus::tool
