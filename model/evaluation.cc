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
  report.rows = {{"model"}, {"identity (output = content)"}, {"copy-style (output = style)"}};
  const motion::HumanoidRoles& roles = model.package().roles;
  double real_skating = 0;
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
    absl::StatusOr<motion::Motion> out = model.Transfer(*content, *code);
    if (!out.ok()) return out.status();
    const motion::Motion* outputs[3] = {&*out, &*content, &*style};
    for (int r = 0; r < 3; ++r) {
      absl::StatusOr<int> s = judges.ClassifyStyle(*outputs[r]);
      if (!s.ok()) return s.status();
      absl::StatusOr<int> c = judges.ClassifyContent(*outputs[r]);
      if (!c.ok()) return c.status();
      report.rows[r].style_accuracy += *s == want_style;
      report.rows[r].content_accuracy += *c == want_content;
      // Copy-style has another length: its skating is measured against itself.
      report.rows[r].foot_skating += motion::FootSkating(*outputs[r], r == 2 ? *style : *content, roles);
      ++report.rows[r].pairs;
    }
    real_skating += motion::FootSkating(*content, *content, roles);
    if (progress) progress(++done, static_cast<int>(pairs.size()));
  }
  for (EvalRow& r : report.rows) {
    r.style_accuracy /= r.pairs;
    r.content_accuracy /= r.pairs;
    r.foot_skating /= r.pairs;
  }
  report.real_foot_skating = real_skating / pairs.size();
  return report;
}

std::string EvalReport::Markdown() const {
  std::string s =
      "| output | pairs | style accuracy | content accuracy | foot skating (units/s) |\n| --- | "
      "--- | --- | --- | --- |\n";
  for (const EvalRow& r : rows) {
    absl::StrAppendFormat(&s, "| %s | %d | %.3f | %.3f | %.2f |\n", r.name, r.pairs,
                          r.style_accuracy, r.content_accuracy, r.foot_skating);
  }
  absl::StrAppendFormat(&s, "\nReal data's own foot skating (content clips): %.2f units/s.\n",
                        real_foot_skating);
  return s;
}

}  // namespace stylus::model
