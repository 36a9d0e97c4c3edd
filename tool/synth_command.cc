// synth.
#include <cstdio>

#include "absl/strings/str_format.h"
#include "model/style_model.h"
#include "motion/bvh.h"
#include "motion/retarget.h"
#include "motion/synth.h"
#include "tool/cli_support.h"
#include "tool/model_spec.h"

namespace stylus::tool {

int Synth(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool synth --style KNOBS [--model DIR] -o FILE\n\n"
      "Synthesizes a walk or run on the Bandai skeleton and writes it as BVH.\n"
      "Its joints' own frames are the synthesizer's (a bone's twist is its own\n"
      "choice), not real capture's: --model DIR writes it in that package's\n"
      "joint frames instead, fitted from the package's reference pose as a clip\n"
      "on another rig is (docs/rigs.md), so the package's networks and judges\n"
      "read it as they read capture on its skeleton.\n"
      "KNOBS is PRESET[,key=value...] or key=value,... e.g. 'old', 'run,speed=400',\n"
      "'lean=12,arm_swing=5,frames=300'.\n"
      "Presets: normal old tired proud happy sneaky run.\n"
      "Keys: gait (walk|run), speed (cm/s), stride (cm per cycle), lean, head_drop,\n"
      "arm_swing, elbow, arm_out (degrees), bounce, foot_lift (cm), crouch (fraction\n"
      "of leg length), sway (cm), turn (deg/s), frames, fps.\n";
  int code = 0;
  auto args = ParseOrExit("synth", argv, {{"style", "out", "model"}, {}}, kHelp, &code);
  if (!args) return code;
  if (!args->Has("out") || !args->positional.empty()) {
    std::fprintf(stderr, "stylus-tool synth: -o FILE is required\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<motion::SynthStyle> style = motion::ParseSynthStyle(args->Get("style", "normal"));
  if (!style.ok()) return Fail("synth", style.status());
  absl::StatusOr<motion::Motion> m = motion::Synthesize(*style);
  if (!m.ok()) return Fail("synth", m.status());
  if (args->Has("model")) {
    absl::StatusOr<std::unique_ptr<model::StyleModel>> package = LoadModelSpec(args->Get("model"));
    if (!package.ok()) return Fail("synth", package.status());
    absl::StatusOr<std::unique_ptr<motion::Retargeter>> r =
        (*package)->RetargeterFor(*m, {}, "the synthesized clip");
    if (!r.ok()) return Fail("synth", r.status());
    *m = (*r)->ToModel(*m);
  }
  if (absl::Status s = motion::WriteBvhFile(*m, args->Get("out")); !s.ok()) return Fail("synth", s);
  absl::PrintF("wrote %s: %d frames at %g fps\n", args->Get("out"), m->num_frames, m->fps());
  return 0;
}

}  // namespace stylus::tool
