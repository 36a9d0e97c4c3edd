#include "tool/part_swap.h"

#include <map>
#include <memory>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/humanoid.h"
#include "motion/splice.h"

namespace stylus::model {
namespace {

// Reads each clip once.
class ClipCache {
 public:
  absl::StatusOr<const motion::Motion*> Get(const std::string& path) {
    auto it = clips_.find(path);
    if (it == clips_.end()) {
      absl::StatusOr<motion::Motion> m = motion::ReadBvhFile(path);
      if (!m.ok()) return m.status();
      it = clips_.emplace(path, std::make_unique<motion::Motion>(*std::move(m))).first;
    }
    return it->second.get();
  }

 private:
  std::map<std::string, std::unique_ptr<motion::Motion>> clips_;
};

std::string Percent(const SwapTestCount& c) {
  return absl::StrFormat("%.3f (%d/%d)", c.accuracy(), c.kept, c.clips);
}

}  // namespace

absl::StatusOr<SwapTestReport> RunSwapTest(const Judges& judges,
                                           const std::vector<std::string>& data,
                                           const std::function<void(int, int)>& progress) {
  absl::StatusOr<motion::DatasetIndex> index = motion::IndexDataset(data);
  if (!index.ok()) return index.status();
  const std::vector<const motion::ClipEntry*> held_out = index->Split(true);
  ClipCache cache;
  SwapTestReport report;
  for (motion::BodyPart p : motion::kBodyParts)
    report.parts.push_back({motion::BodyPartName(p), {}, {}});
  std::map<std::string, SwapTestCount> by_action;
  // Whether the judge reads held-out clip c's own content in `clip`.
  auto kept = [&](const motion::Motion& clip, const motion::ClipEntry& c) -> absl::StatusOr<bool> {
    absl::StatusOr<int> verdict = judges.ClassifyContent(clip);
    if (!verdict.ok()) {
      return absl::Status(verdict.status().code(),
                          absl::StrCat(c.path, ": ", verdict.status().message()));
    }
    return judges.contents()[*verdict] == c.label.content;
  };
  auto count = [](bool kept, SwapTestCount* n) {
    ++n->clips;
    n->kept += kept;
  };
  for (size_t i = 0; i < held_out.size(); ++i) {
    const motion::ClipEntry& c = *held_out[i];
    absl::StatusOr<const motion::Motion*> base = cache.Get(c.path);
    if (!base.ok()) return base.status();
    absl::StatusOr<bool> unchanged = kept(**base, c);
    if (!unchanged.ok()) return unchanged.status();
    count(*unchanged, &report.unchanged);
    absl::StatusOr<motion::HumanoidRoles> roles = motion::FindHumanoidRoles((*base)->skeleton);
    if (!roles.ok())
      return absl::InvalidArgumentError(absl::StrCat(c.path, ": ", roles.status().message()));
    for (size_t k = 0; k < report.parts.size(); ++k) {
      const std::vector<int> joints =
          motion::BodyPartJoints((*base)->skeleton, *roles, motion::kBodyParts[k]);
      for (bool same_action : {true, false}) {
        // Candidates in index order (sorted by path); long enough ones only.
        std::vector<const motion::ClipEntry*> donors;
        for (const motion::ClipEntry& d : index->clips) {
          if (d.label.dataset != c.label.dataset || d.path == c.path) continue;
          const bool fits =
              same_action ? (d.label.content == c.label.content && d.label.style != c.label.style)
                          : (d.label.content != c.label.content && d.label.style == c.label.style);
          if (!fits) continue;
          absl::StatusOr<const motion::Motion*> m = cache.Get(d.path);
          if (!m.ok()) return m.status();
          if ((*m)->num_frames >= (*base)->num_frames) donors.push_back(&d);
        }
        if (donors.empty()) continue;
        const motion::ClipEntry& donor = *donors[(i * 7 + k * 3) % donors.size()];
        absl::StatusOr<motion::Motion> spliced =
            motion::SpliceJoints(**base, **cache.Get(donor.path), joints, c.path, donor.path);
        if (!spliced.ok()) return spliced.status();
        absl::StatusOr<bool> verdict = kept(*spliced, c);
        if (!verdict.ok()) return verdict.status();
        SwapTestRow& row = report.parts[k];
        count(*verdict, same_action ? &row.same_action : &row.other_action);
        if (same_action) count(*verdict, &by_action[c.label.content]);
      }
    }
    if (progress) progress(static_cast<int>(i + 1), static_cast<int>(held_out.size()));
  }
  report.by_action.assign(by_action.begin(), by_action.end());
  return report;
}

std::string SwapTestReport::Markdown() const {
  std::string s = absl::StrCat(
      "Content judge, body-part swap test (held-out real clips; each gets one body part of "
      "another real clip of the same dataset)\n\nUnchanged clips: ",
      Percent(unchanged),
      "\n\n| part swapped | donor: same action, another style | donor: another action, same "
      "style |\n| --- | --- | --- |\n");
  for (const SwapTestRow& r : parts) {
    absl::StrAppend(&s, "| ", r.part, " | ", Percent(r.same_action), " | ", Percent(r.other_action),
                    " |\n");
  }
  absl::StrAppend(&s,
                  "\nBy action, same-action donors (all parts):\n\n| action | kept |\n| --- | --- "
                  "|\n");
  for (const auto& [action, count] : by_action) {
    absl::StrAppend(&s, "| ", action, " | ", Percent(count), " |\n");
  }
  return s;
}

}  // namespace stylus::model
