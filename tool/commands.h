// stylus-tool subcommands. Each takes the arguments after its name, prints its
// results to stdout and errors to stderr, and returns the process exit code
// (0 ok, 1 failure, 2 bad usage).
#ifndef STYLUS_TOOL_COMMANDS_H_
#define STYLUS_TOOL_COMMANDS_H_

#include <string>
#include <vector>

namespace stylus::tool {

using Argv = std::vector<std::string>;

int BvhInfo(const Argv& argv);
int BvhRoundtrip(const Argv& argv);
int BvhMirror(const Argv& argv);
int BvhSplice(const Argv& argv);
int Features(const Argv& argv);
int DatasetStats(const Argv& argv);
int Synth(const Argv& argv);
int Render(const Argv& argv);
int Train(const Argv& argv);
int TrainCyclicModel(const Argv& argv);  // train --family cyclic.
int Transfer(const Argv& argv);
int RigInfo(const Argv& argv);
int TrainJudges(const Argv& argv);
int TrainGuard(const Argv& argv);
int Eval(const Argv& argv);
int Judge(const Argv& argv);
int StyleMap(const Argv& argv);
int Trajectories(const Argv& argv);
int Gait(const Argv& argv);

}  // namespace stylus::tool

#endif  // STYLUS_TOOL_COMMANDS_H_
