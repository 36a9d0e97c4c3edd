// trajectories: root paths of content clips and their transfers, seen from
// above, as SVG (paper 004's Fig. 5-6 analogue).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "model/runtime.h"
#include "motion/features.h"
#include "motion/files.h"
#include "tool/cli_support.h"
#include "tool/model_spec.h"
#include "tool/svg_plot.h"

namespace stylus::tool {
namespace {

struct Path {
  std::string label, colour;
  std::vector<std::pair<double, double>> points;  // Floor (x, z) per frame.
};

Path RootPath(const motion::Motion& m, const motion::HumanoidRoles& roles, std::string label,
              std::string colour) {
  Path p{std::move(label), std::move(colour), {}};
  for (int f = 0; f < m.num_frames; ++f) {
    const motion::RootStart r = motion::RootAt(m, roles, f);
    p.points.push_back({r.x, r.z});
  }
  return p;
}

// One panel: every path scaled into a square with a common scale, content
// first, start points marked.
std::string Panel(const std::string& content_name, const std::string& style_name,
                  const std::vector<Path>& paths, double x0, double size) {
  double lo_x = 1e300, hi_x = -1e300, lo_z = 1e300, hi_z = -1e300;
  for (const Path& p : paths)
    for (const auto& [x, z] : p.points) {
      lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x);
      lo_z = std::min(lo_z, z), hi_z = std::max(hi_z, z);
    }
  const double span = std::max({hi_x - lo_x, hi_z - lo_z, 1e-6});
  const double margin = 30, inner = size - 2 * margin, scale = inner / span;
  const double cx = (lo_x + hi_x) / 2, cz = (lo_z + hi_z) / 2;
  auto px = [&](double x) { return x0 + margin + inner / 2 + (x - cx) * scale; };
  auto py = [&](double z) { return 40 + margin + inner / 2 - (z - cz) * scale; };
  std::string s = absl::StrFormat(
      "<rect x='%.1f' y='40' width='%.1f' height='%.1f' fill='none' stroke='#ccc'/>\n"
      "<text x='%.1f' y='22' font-size='11' text-anchor='middle'>content: %s</text>\n"
      "<text x='%.1f' y='35' font-size='11' text-anchor='middle'>style: %s</text>\n",
      x0, size, size, x0 + size / 2, content_name, x0 + size / 2, style_name);
  // Compared models first, the model above them, the content dashed on top.
  std::vector<const Path*> order;
  for (size_t i = paths.size(); i-- > 1;) order.push_back(&paths[i]);
  order.push_back(&paths[0]);
  for (const Path* path : order) {
    const Path& p = *path;
    const bool content = path == &paths[0];
    std::string pts;
    for (const auto& [x, z] : p.points)
      absl::StrAppend(&pts, absl::StrFormat("%.1f,%.1f ", px(x), py(z)));
    absl::StrAppendFormat(&s,
                          "<polyline fill='none' stroke='%s' stroke-width='%s' %spoints='%s'/>\n",
                          p.colour, content ? "1.5" : "2.5",
                          content ? "stroke-dasharray='6 4' " : "stroke-opacity='0.85' ", pts);
    if (!p.points.empty()) {
      absl::StrAppendFormat(&s, "<circle cx='%.1f' cy='%.1f' r='4' fill='%s'/>\n",
                            px(p.points[0].first), py(p.points[0].second), p.colour);
    }
  }
  absl::StrAppendFormat(&s,
                        "<text x='%.1f' y='%.1f' font-size='11' fill='#666'>scale: %.0f units "
                        "across</text>\n",
                        x0 + 6, 40 + size - 8, span);
  return s;
}

}  // namespace

int Trajectories(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool trajectories --model DIR[:KEY=VALUE] --pair CONTENT.bvh,STYLE.bvh...\n"
      "         [--compare LABEL=DIR[:KEY=VALUE]]... [--postprocess none|feet|full] -o OUT.svg\n\n"
      "Transfers each pair with the model (and each --compare model) and draws\n"
      "the root's path on the floor, seen from above, one panel per pair: the\n"
      "content clip dashed, the outputs in colour, start points as dots (paper\n"
      "004's trajectory figures). --postprocess defaults to none, to show the\n"
      "model's own trajectory.\n";
  int code = 0;
  auto args = ParseOrExit("trajectories", argv,
                          {{"model", "pair", "compare", "postprocess", "out", "threads"}, {}},
                          kHelp, &code);
  if (!args) return code;
  if (!args->Has("model") || !args->Has("pair") || !args->Has("out")) {
    std::fprintf(stderr, "stylus-tool trajectories: --model, --pair and -o are required\n\n%s",
                 kHelp);
    return 2;
  }
  absl::StatusOr<int> threads = args->GetInt("threads", 0);
  if (!threads.ok()) return Fail("trajectories", threads.status());
  model::SetComputeThreads(*threads);
  absl::StatusOr<motion::PostProcessMode> post =
      motion::ParsePostProcessMode(args->Get("postprocess", "none"));
  if (!post.ok()) return Fail("trajectories", post.status());
  absl::StatusOr<std::vector<NamedModel>> models =
      LoadModelAndComparisons(args->Get("model"), args->All("compare"));
  if (!models.ok()) return Fail("trajectories", models.status());
  const double size = 360;
  std::string body;
  int panel = 0;
  for (const std::string& pair : args->All("pair")) {
    absl::StatusOr<ClipPair> clips = ReadClipPair(pair);
    if (!clips.ok()) return Fail("trajectories", clips.status());
    const motion::Motion &content = clips->content, &style = clips->style;
    const motion::HumanoidRoles& roles = (*models)[0].model->data().roles;
    std::vector<Path> paths = {RootPath(content, roles, "content", "#000")};
    absl::StatusOr<std::vector<motion::Motion>> outputs =
        TransferWithEach(*models, content, style, *post);
    if (!outputs.ok()) return Fail("trajectories", outputs.status());
    for (size_t i = 0; i < models->size(); ++i)
      paths.push_back(RootPath((*outputs)[i], roles, (*models)[i].label, ModelColour(i)));
    body += Panel(std::filesystem::path(clips->content_path).stem().string(),
                  std::filesystem::path(clips->style_path).stem().string(), paths, 10 + panel * (size + 20),
                  size);
    ++panel;
  }
  const double width = 20 + panel * (size + 20);
  std::vector<std::pair<std::string, std::string>> keys = {{"content (dashed)", "#000"}};
  for (size_t i = 0; i < models->size(); ++i) keys.push_back({(*models)[i].label, ModelColour(i)});
  double right = 0;
  const std::string legend = SvgLegend(keys, size + 54, &right);
  const std::string svg = SvgDocument(
      std::max(width, right + 10), size + 100,
      absl::StrFormat("<text x='10' y='%.0f' font-size='12' fill='#444'>Root trajectories seen "
                      "from above (postprocess %s)</text>\n%s%s",
                      size + 92, motion::PostProcessModeName(*post), body, legend));
  if (absl::Status s = motion::WriteFileAtomically(args->Get("out"), svg); !s.ok())
    return Fail("trajectories", s);
  absl::PrintF("wrote %s (%d panels)\n", args->Get("out"), panel);
  return 0;
}

}  // namespace stylus::tool
