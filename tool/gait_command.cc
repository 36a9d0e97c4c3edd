// gait: how transfers move against their content and style clips, as curves
// over time (stride, foot lift, arm swing, pelvis bob; motion/gait.h) in SVG
// and as a Markdown table of the curves' spreads, the cadence and the speed.
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "model/runtime.h"
#include "motion/files.h"
#include "motion/gait.h"
#include "motion/postprocess.h"
#include "motion/rig_roles.h"
#include "tool/cli_support.h"
#include "tool/model_spec.h"
#include "tool/svg_plot.h"

namespace stylus::tool {
namespace {

struct Series {
  std::string label, colour;
  bool dashed = false;
  motion::GaitCurves curves;
  motion::GaitSummary summary;
};

// One curve of GaitCurves and its panel's title.
struct Measure {
  const char* title;
  std::vector<double> motion::GaitCurves::*curve;
};
const Measure kMeasures[] = {
    {"stride: left ankle ahead of the pelvis", &motion::GaitCurves::foot_forward},
    {"foot lift: left ankle height", &motion::GaitCurves::foot_height},
    {"arm swing: left hand ahead of the pelvis", &motion::GaitCurves::hand_forward},
    {"bob: pelvis height", &motion::GaitCurves::pelvis_height},
};
constexpr double kPanelW = 280, kPanelH = 140, kGap = 24, kRowTitle = 34, kRowH = kPanelH + 60;

// `clip` measured (its own rig's roles); errors start with `name`.
absl::StatusOr<Series> Measured(const motion::Motion& clip, const std::string& name,
                                std::string label, std::string colour, bool dashed) {
  absl::StatusOr<motion::HumanoidRoles> roles = motion::HumanoidRolesOf(clip);
  absl::StatusOr<motion::Gait> gait =
      roles.ok() ? motion::MeasureGait(clip, *roles) : absl::StatusOr<motion::Gait>(roles.status());
  if (!gait.ok()) {
    return absl::Status(gait.status().code(), absl::StrCat(name, ": ", gait.status().message()));
  }
  return Series{std::move(label), std::move(colour), dashed, std::move(gait->curves),
                gait->summary};
}

// Frames of `s` within the first `seconds`.
size_t Shown(const Series& s, double seconds) {
  const size_t n = s.curves.foot_forward.size();
  return std::min(n, static_cast<size_t>(seconds / s.curves.frame_time) + 1);
}

// One panel: every series' curve on common axes, seconds across.
std::string Panel(const Measure& m, const std::vector<Series>& series, double seconds, double x0,
                  double y0) {
  double duration = 0, lo = 1e300, hi = -1e300;
  for (const Series& s : series) {
    const std::vector<double>& v = s.curves.*m.curve;
    const size_t n = Shown(s, seconds);
    duration = std::max(duration, (n - 1) * s.curves.frame_time);
    for (size_t f = 0; f < n; ++f) lo = std::min(lo, v[f]), hi = std::max(hi, v[f]);
  }
  const double pad = std::max(0.05 * (hi - lo), 1e-3);
  lo -= pad, hi += pad;
  duration = std::max(duration, 1e-3);
  auto px = [&](double t) { return x0 + t / duration * kPanelW; };
  auto py = [&](double v) { return y0 + kPanelH - (v - lo) / (hi - lo) * kPanelH; };
  std::string s = absl::StrFormat(
      "<rect x='%.1f' y='%.1f' width='%.1f' height='%.1f' fill='none' stroke='#ccc'/>\n"
      "<text x='%.1f' y='%.1f' font-size='11'>%s</text>\n",
      x0, y0, kPanelW, kPanelH, x0, y0 - 5, m.title);
  if (lo < 0 && hi > 0) {
    absl::StrAppendFormat(&s, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='#eee'/>\n",
                          x0, py(0), x0 + kPanelW, py(0));
  }
  // The style and the outputs first, the content dashed on top.
  for (int pass = 0; pass < 2; ++pass) {
    for (const Series& ser : series) {
      if (ser.dashed != (pass == 1)) continue;
      const std::vector<double>& v = ser.curves.*m.curve;
      std::string pts;
      for (size_t f = 0; f < Shown(ser, seconds); ++f)
        absl::StrAppendFormat(&pts, "%.1f,%.1f ", px(f * ser.curves.frame_time), py(v[f]));
      absl::StrAppendFormat(&s, "<polyline fill='none' stroke='%s' stroke-width='%s' %spoints='%s'/>\n",
                            ser.colour, ser.dashed ? "1.5" : "2",
                            ser.dashed ? "stroke-dasharray='5 3' " : "stroke-opacity='0.85' ",
                            pts);
    }
  }
  absl::StrAppendFormat(&s,
                        "<text x='%.1f' y='%.1f' font-size='10' fill='#666'>%.2f s; %.2f leg "
                        "lengths high</text>\n",
                        x0, y0 + kPanelH + 13, duration, hi - lo);
  return s;
}

std::string TableRow(const std::string& pair, const Series& s) {
  const std::string period =
      s.summary.cadence ? absl::StrFormat("%.2f%s", s.summary.cadence->period_s,
                                          s.summary.cadence->source == motion::Cadence::Source::kSteps
                                              ? ""
                                              : " (motion)")
                        : "-";
  return absl::StrFormat("| %s | %s | %s | %.2f | %.3f | %.3f | %.3f | %.3f |\n", pair, s.label,
                         period, s.summary.speed, s.summary.stride, s.summary.foot_lift,
                         s.summary.arm_swing, s.summary.bob);
}

}  // namespace

int Gait(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool gait --model DIR[:KEY=VALUE] --pair CONTENT.bvh,STYLE.bvh...\n"
      "         [--compare LABEL=DIR[:KEY=VALUE]]... [--postprocess none|feet|full]\n"
      "         [--seconds 4] [--threads N] -o OUT.svg\n\n"
      "Transfers each pair with the model (and each --compare model) and shows how\n"
      "the outputs move against the content and the style clip: one row of\n"
      "curves over time per pair (the left ankle and hand ahead of the pelvis\n"
      "along the facing direction: stride and arm swing; the left ankle's\n"
      "height: foot lift; the pelvis's height: bob), the content dashed, the\n"
      "style grey, the outputs in colour. Prints a Markdown table per clip:\n"
      "seconds per step (from the feet; '(motion)' when the clip does not step\n"
      "and its motion repeats), speed, and each curve's spread (95th minus 5th\n"
      "percentile) over the whole clip, all in leg lengths (per second).\n"
      "--seconds S draws the first S seconds of each clip (all: 0). --postprocess\n"
      "defaults to full, as stylus-tool eval's targets are read.\n";
  int code = 0;
  auto args = ParseOrExit("gait", argv,
                          {{"model", "pair", "compare", "postprocess", "out", "threads", "seconds"}, {}},
                          kHelp, &code);
  if (!args) return code;
  if (!args->Has("model") || !args->Has("pair") || !args->Has("out")) {
    std::fprintf(stderr, "stylus-tool gait: --model, --pair and -o are required\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<int> threads = args->GetInt("threads", 0);
  if (!threads.ok()) return Fail("gait", threads.status());
  model::SetComputeThreads(*threads);
  absl::StatusOr<double> seconds = args->GetDouble("seconds", 4);
  if (!seconds.ok()) return Fail("gait", seconds.status());
  if (*seconds < 0) return Fail("gait", absl::InvalidArgumentError("--seconds must be 0 or more"));
  if (*seconds == 0) *seconds = 1e9;
  absl::StatusOr<motion::PostProcessMode> post =
      motion::ParsePostProcessMode(args->Get("postprocess", "full"));
  if (!post.ok()) return Fail("gait", post.status());
  absl::StatusOr<std::vector<NamedModel>> models =
      LoadModelAndComparisons(args->Get("model"), args->All("compare"));
  if (!models.ok()) return Fail("gait", models.status());
  std::string body,
      table = "| pair | clip | s per step | speed | stride | foot lift | arm swing | bob |\n"
              "| --- | --- | --- | --- | --- | --- | --- | --- |\n";
  int row = 0;
  for (const std::string& pair : args->All("pair")) {
    absl::StatusOr<ClipPair> clips = ReadClipPair(pair);
    if (!clips.ok()) return Fail("gait", clips.status());
    const std::string content_name = std::filesystem::path(clips->content_path).stem().string();
    const std::string style_name = std::filesystem::path(clips->style_path).stem().string();
    std::vector<Series> series;
    for (absl::StatusOr<Series> s :
         {Measured(clips->content, clips->content_path, "content", "#000", true),
          Measured(clips->style, clips->style_path, "style", "#999", false)}) {
      if (!s.ok()) return Fail("gait", s.status());
      series.push_back(*std::move(s));
    }
    absl::StatusOr<std::vector<motion::Motion>> outputs =
        TransferWithEach(*models, clips->content, clips->style, *post);
    if (!outputs.ok()) return Fail("gait", outputs.status());
    for (size_t i = 0; i < models->size(); ++i) {
      absl::StatusOr<Series> s = Measured((*outputs)[i], (*models)[i].label, (*models)[i].label,
                                          ModelColour(i), false);
      if (!s.ok()) return Fail("gait", s.status());
      series.push_back(*std::move(s));
    }
    const double y0 = 40 + row * (kRowH + kRowTitle);
    absl::StrAppendFormat(&body, "<text x='10' y='%.1f' font-size='12'>content: %s, style: %s</text>\n",
                          y0 + 12, content_name, style_name);
    for (size_t k = 0; k < std::size(kMeasures); ++k) {
      body += Panel(kMeasures[k], series, *seconds, 10 + k * (kPanelW + kGap), y0 + kRowTitle);
    }
    for (const Series& s : series) table += TableRow(content_name + " / " + style_name, s);
    ++row;
  }
  const double width = 20 + std::size(kMeasures) * (kPanelW + kGap);
  const double legend_y = 40 + row * (kRowH + kRowTitle) + 10;
  std::vector<std::pair<std::string, std::string>> keys = {{"content (dashed)", "#000"},
                                                           {"style", "#999"}};
  for (size_t i = 0; i < models->size(); ++i) keys.push_back({(*models)[i].label, ModelColour(i)});
  double right = 0;
  const std::string legend = SvgLegend(keys, legend_y, &right);
  const std::string svg = SvgDocument(
      std::max(width, right + 10), legend_y + 30,
      absl::StrFormat("<text x='10' y='20' font-size='13' fill='#444'>How the body moves, in leg "
                      "lengths (postprocess %s)</text>\n%s%s",
                      motion::PostProcessModeName(*post), body, legend));
  if (absl::Status s = motion::WriteFileAtomically(args->Get("out"), svg); !s.ok())
    return Fail("gait", s);
  absl::PrintF("%swrote %s (%d pairs)\n", table, args->Get("out"), row);
  return 0;
}

}  // namespace stylus::tool
