#include "model/evaluation.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "motion/bvh.h"
#include "motion/contacts.h"
#include "motion/dataset.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"

namespace stylus::model {
namespace {

std::string FileName(const std::string& p) { return std::filesystem::path(p).filename().string(); }

}  // namespace

absl::StatusOr<std::vector<EvalPair>> MakeEvalPairs(const std::vector<std::string>& dirs,
                                                    int per_content) {
  absl::StatusOr<motion::DatasetIndex> index = motion::IndexDataset(dirs);
  if (!index.ok()) return index.status();
  const std::vector<const motion::ClipEntry*> test = index->Split(true);
  std::vector<EvalPair> pairs;
  for (const motion::ClipEntry* c : test) {
    std::vector<const motion::ClipEntry*> styles;
    for (const motion::ClipEntry* s : test) {
      if (s->label.content != c->label.content && s->label.style != c->label.style)
        styles.push_back(s);
    }
    const std::string cname = FileName(c->path);
    std::sort(styles.begin(), styles.end(),
              [&](const motion::ClipEntry* a, const motion::ClipEntry* b) {
                return motion::StableHash(cname + FileName(a->path)) <
                       motion::StableHash(cname + FileName(b->path));
              });
    for (int i = 0; i < per_content && i < static_cast<int>(styles.size()); ++i) {
      pairs.push_back({c->path, styles[i]->path});
    }
  }
  if (pairs.empty()) return absl::NotFoundError("no held-out pairs of different content and style");
  return pairs;
}

absl::StatusOr<EvalReport> Evaluate(const ContrastiveModel& model, const Judges& judges,
                                    const std::vector<EvalPair>& pairs,
                                    const std::function<void(int, int)>& progress) {
  EvalReport report;
  report.rows = {{"model, no post-processing"},
                 {"model, post-processing full"},
                 {"identity (output = content)"},
                 {"copy-style (output = style)"}};
  const motion::HumanoidRoles& roles = model.package().roles;
  int done = 0;
  for (const EvalPair& p : pairs) {
    absl::StatusOr<motion::Motion> content = motion::ReadBvhFile(p.content_path);
    if (!content.ok()) return content.status();
    absl::StatusOr<motion::Motion> style = motion::ReadBvhFile(p.style_path);
    if (!style.ok()) return style.status();
    const auto style_label = motion::ParseClipName(p.style_path),
               content_label = motion::ParseClipName(p.content_path);
    if (!style_label || !content_label)
      return absl::InvalidArgumentError("pair without labels: " + p.content_path);
    const auto& styles = judges.styles();
    const auto& contents = judges.contents();
    const int want_style = static_cast<int>(
        std::find(styles.begin(), styles.end(), style_label->style) - styles.begin());
    const int want_content = static_cast<int>(
        std::find(contents.begin(), contents.end(), content_label->content) - contents.begin());
    absl::StatusOr<StyleCode> code = model.EncodeStyle(*style);
    if (!code.ok()) return code.status();
    absl::StatusOr<motion::Motion> raw =
        model.Transfer(*content, *code, motion::PostProcessMode::kNone);
    if (!raw.ok()) return raw.status();
    absl::StatusOr<motion::Motion> full =
        motion::PostProcess(*raw, *content, roles, motion::PostProcessMode::kFull);
    if (!full.ok()) return full.status();
    const motion::Motion* outputs[4] = {&*raw, &*full, &*content, &*style};
    for (int r = 0; r < 4; ++r) {
      absl::StatusOr<int> s = judges.ClassifyStyle(*outputs[r]);
      if (!s.ok()) return s.status();
      absl::StatusOr<int> c = judges.ClassifyContent(*outputs[r]);
      if (!c.ok()) return c.status();
      EvalRow& row = report.rows[r];
      row.style_accuracy += *s == want_style;
      row.content_accuracy += *c == want_content;
      // Copy-style has another length: its feet are measured against itself.
      const motion::Motion& planted = r == 3 ? *style : *content;
      row.foot_skating += motion::FootSkating(*outputs[r], planted, roles);
      row.foot_height_error += motion::FootHeightError(*outputs[r], planted, roles);
      row.bone_length_error += motion::BoneLengthError(*outputs[r], roles);
      row.jitter += motion::Jitter(*outputs[r]);
      row.euler_discontinuities += motion::EulerDiscontinuities(*outputs[r]);
      ++row.pairs;
    }
    if (progress) progress(++done, static_cast<int>(pairs.size()));
  }
  for (EvalRow& r : report.rows) {
    r.style_accuracy /= r.pairs;
    r.content_accuracy /= r.pairs;
    r.foot_skating /= r.pairs;
    r.foot_height_error /= r.pairs;
    r.bone_length_error /= r.pairs;
    r.jitter /= r.pairs;
  }
  return report;
}

std::string EvalReport::Markdown() const {
  std::string s =
      "| output | pairs | style accuracy | content accuracy |\n| --- | --- | --- | --- |\n";
  for (const EvalRow& r : rows) {
    absl::StrAppendFormat(&s, "| %s | %d | %.3f | %.3f |\n", r.name, r.pairs, r.style_accuracy,
                          r.content_accuracy);
  }
  s +=
      "\nKinematics (means over pairs; feet measured where the content clip's feet are "
      "planted, copy-style against the style clip itself):\n\n"
      "| output | foot skating (units/s) | foot height error (units) | bone length error | "
      "jitter (units/s^3) | Euler discontinuities |\n| --- | --- | --- | --- | --- | --- |\n";
  for (const EvalRow& r : rows) {
    absl::StrAppendFormat(&s, "| %s | %.2f | %.2f | %.4f%% | %.0f | %d |\n", r.name,
                          r.foot_skating, r.foot_height_error, 100 * r.bone_length_error,
                          r.jitter, r.euler_discontinuities);
  }
  if (rows.size() >= 3) {
    const EvalRow &full = rows[1], &real = rows[2];
    absl::StrAppendFormat(
        &s,
        "\nPost-processed against real data (identity row): foot skating %.2fx (target <= 1.2x), "
        "jitter %.2fx (target <= 1.5x), bone length error %.4f%% (target < 0.1%%), Euler "
        "discontinuities %d (real data: %d).\n",
        full.foot_skating / std::max(real.foot_skating, 1e-9),
        full.jitter / std::max(real.jitter, 1e-9), 100 * full.bone_length_error,
        full.euler_discontinuities, real.euler_discontinuities);
  }
  return s;
}

}  // namespace stylus::model
