// stylus-tool: the offline tool (BVH inspection, dataset statistics, synthesis).
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "tool/commands.h"

namespace {

struct Command {
  const char* name;
  int (*run)(const stylus::tool::Argv&);
  const char* summary;
};

const Command kCommands[] = {
    {"bvh-info", stylus::tool::BvhInfo, "joints, frames, fps and channel layout of a BVH file"},
    {"bvh-roundtrip", stylus::tool::BvhRoundtrip,
     "read, write and re-read a BVH; report the FK error"},
    {"bvh-mirror", stylus::tool::BvhMirror, "mirror a clip left to right on its own skeleton"},
    {"bvh-splice", stylus::tool::BvhSplice,
     "take body parts (legs, torso, an arm) from another clip"},
    {"features", stylus::tool::Features,
     "feature summary of a clip (and its features->motion error)"},
    {"dataset-stats", stylus::tool::DatasetStats, "clips, frames and counts per content and style"},
    {"synth", stylus::tool::Synth, "synthesize a styled walk or run on the Bandai skeleton"},
    {"render", stylus::tool::Render, "draw a clip as a filmstrip of stick figures (SVG)"},
    {"train", stylus::tool::Train, "train a style-transfer model (family contrastive or cyclic)"},
    {"transfer", stylus::tool::Transfer, "transfer a style clip onto a content clip with a model"},
    {"rig-info", stylus::tool::RigInfo, "how a BVH file's rig maps onto a model's skeleton"},
    {"train-judges", stylus::tool::TrainJudges,
     "train the style and content classifiers used by eval"},
    {"train-guard", stylus::tool::TrainGuard,
     "train a contrastive package's content guard (keeps the action)"},
    {"judge", stylus::tool::Judge,
     "what the judges read in clips: styles and contents, likeliest first"},
    {"eval", stylus::tool::Eval, "evaluate a model on held-out pairs against baselines"},
    {"style-map", stylus::tool::StyleMap, "plot style codes of labelled clips (PCA, SVG)"},
    {"trajectories", stylus::tool::Trajectories,
     "plot root paths of content clips and their transfers (SVG)"},
    {"gait", stylus::tool::Gait,
     "how transfers move: stride, foot lift, arm swing, bob (SVG, table)"},
};

void Usage(FILE* out) {
  std::fprintf(
      out, "usage: stylus-tool COMMAND [ARGS...]   (stylus-tool COMMAND --help for details)\n\n");
  for (const Command& c : kCommands) std::fprintf(out, "  %-15s %s\n", c.name, c.summary);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    Usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::vector<std::string> rest(argv + 2, argv + argc);
  for (const Command& c : kCommands) {
    if (argv[1] == std::string(c.name)) return c.run(rest);
  }
  std::fprintf(stderr, "stylus-tool: unknown command '%s'\n\n", argv[1]);
  Usage(stderr);
  return 2;
}
