// trajectories: root paths of content clips and their transfers, seen from
// above, as SVG (paper 004's Fig. 5-6 analogue).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "model/runtime.h"
#include "motion/bvh.h"
#include "motion/features.h"
#include "motion/files.h"
#include "tool/cli_support.h"
#include "tool/model_spec.h"

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
  std::vector<std::pair<std::string, std::unique_ptr<model::StyleModel>>> models;
  auto main_model = LoadModelSpec(args->Get("model"));
  if (!main_model.ok()) return Fail("trajectories", main_model.status());
  models.emplace_back(args->Get("model"), *std::move(main_model));
  for (const std::string& spec : args->All("compare")) {
    const size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0) {
      return Fail("trajectories",
                  absl::InvalidArgumentError("--compare wants LABEL=DIR, got '" + spec + "'"));
    }
    auto m = LoadModelSpec(spec.substr(eq + 1));
    if (!m.ok()) return Fail("trajectories", m.status());
    models.emplace_back(spec.substr(0, eq), *std::move(m));
  }
  static const char* kColours[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e"};
  const double size = 360;
  std::string body;
  int panel = 0;
  for (const std::string& pair : args->All("pair")) {
    const std::vector<std::string> files = absl::StrSplit(pair, ',');
    if (files.size() != 2) {
      return Fail("trajectories", absl::InvalidArgumentError(
                                      "--pair wants CONTENT.bvh,STYLE.bvh, got '" + pair + "'"));
    }
    absl::StatusOr<motion::Motion> content = motion::ReadBvhFile(files[0]);
    if (!content.ok()) return Fail("trajectories", content.status());
    absl::StatusOr<motion::Motion> style = motion::ReadBvhFile(files[1]);
    if (!style.ok()) return Fail("trajectories", style.status());
    const motion::HumanoidRoles& roles = models[0].second->data().roles;
    std::vector<Path> paths = {RootPath(*content, roles, "content", "#000")};
    for (size_t i = 0; i < models.size(); ++i) {
      const model::StyleModel& m = *models[i].second;
      absl::StatusOr<model::StyleCode> code = m.EncodeStyle(*style);
      if (!code.ok()) return Fail("trajectories", code.status());
      absl::StatusOr<model::TransferResult> out = m.Transfer(*content, *code, *post);
      if (!out.ok()) return Fail("trajectories", out.status());
      paths.push_back(RootPath(out->motion, roles, models[i].first, kColours[i % 5]));
    }
    body += Panel(std::filesystem::path(files[0]).stem().string(),
                  std::filesystem::path(files[1]).stem().string(), paths, 10 + panel * (size + 20),
                  size);
    ++panel;
  }
  const double width = 20 + panel * (size + 20);
  std::string legend;
  double lx = 10;
  std::vector<std::pair<std::string, std::string>> keys = {{"content (dashed)", "#000"}};
  for (size_t i = 0; i < models.size(); ++i) keys.push_back({models[i].first, kColours[i % 5]});
  for (const auto& [label, colour] : keys) {
    absl::StrAppendFormat(&legend,
                          "<rect x='%.1f' y='%.1f' width='14' height='4' fill='%s'/>"
                          "<text x='%.1f' y='%.1f' font-size='12'>%s</text>\n",
                          lx, size + 54, colour, lx + 18, size + 60, label);
    lx += 30 + 7.0 * label.size();
  }
  const std::string svg = absl::StrFormat(
      "<svg xmlns='http://www.w3.org/2000/svg' width='%.0f' height='%.0f' "
      "font-family='sans-serif'>\n<rect width='100%%' height='100%%' fill='white'/>\n"
      "<text x='10' y='%.0f' font-size='12' fill='#444'>Root trajectories seen from above "
      "(postprocess %s)</text>\n%s%s</svg>\n",
      std::max(width, lx + 10), size + 100, size + 92, motion::PostProcessModeName(*post), body,
      legend);
  if (absl::Status s = motion::WriteFileAtomically(args->Get("out"), svg); !s.ok())
    return Fail("trajectories", s);
  absl::PrintF("wrote %s (%d panels)\n", args->Get("out"), panel);
  return 0;
}

}  // namespace stylus::tool
