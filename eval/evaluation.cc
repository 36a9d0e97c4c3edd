#include "eval/evaluation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <filesystem>
#include <map>
#include <optional>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "motion/bvh.h"
#include "motion/cadence.h"
#include "motion/contacts.h"
#include "motion/dataset.h"
#include "motion/example_motion.h"
#include "motion/gait.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"

namespace stylus::model {
namespace {

std::string FileName(const std::string& p) { return std::filesystem::path(p).filename().string(); }

// How far (leg lengths) any foot joint of `clip` goes below the floor of
// `reference` (the lowest its foot joints reach); 0 when none does.
double BelowFloor(const motion::Motion& clip, const motion::Motion& reference,
                  const motion::HumanoidRoles& roles) {
  const std::array<int, 4> feet = motion::FootJoints(roles);
  double floor = 1e300, lowest = 1e300;
  for (const auto& p : motion::GlobalPositions(reference)) {
    for (int j : feet) floor = std::min(floor, p[j].y);
  }
  for (const auto& p : motion::GlobalPositions(clip)) {
    for (int j : feet) lowest = std::min(lowest, p[j].y);
  }
  return std::max(0.0, floor - lowest) / std::max(roles.leg_length, 1e-9);
}

// One set of judges' labels for one output, and whether each is the pair's.
struct Verdict {
  std::string style, content;
  bool style_right = false, content_right = false;
};

// A stepping clip's gait figures (kGaitFigures), or nullopt when it does not
// step.
std::optional<std::array<double, 5>> GaitFigures(const motion::Motion& clip,
                                                 const motion::HumanoidRoles& roles) {
  absl::StatusOr<motion::Gait> gait = motion::MeasureGait(clip, roles);
  if (!gait.ok()) return std::nullopt;
  const motion::GaitSummary& g = gait->summary;
  if (!g.cadence || g.cadence->source != motion::Cadence::Source::kSteps) return std::nullopt;
  return std::array<double, 5>{g.cadence->period_s, g.stride, g.foot_lift, g.arm_swing, g.bob};
}

// A clip's gesture figures (kGestureFigures), or nullopt when it steps.
std::optional<std::array<double, 2>> GestureFigures(const motion::Motion& clip,
                                                    const motion::HumanoidRoles& roles) {
  absl::StatusOr<motion::MovementClip> m = motion::AnalyzeMovement(clip, roles);
  if (!m.ok() || m->steps) return std::nullopt;
  return std::array<double, 2>{m->hand_speed, std::max(m->hand_reach[0], m->hand_reach[1])};
}

// A Markdown table of each row's shares of the content-to-style gap.
template <size_t N>
void AppendShares(std::string* s, const std::string& intro, const char* const (&names)[N],
                  const std::vector<EvalRow>& rows, std::array<double, N> EvalRow::*share,
                  std::array<int, N> EvalRow::*pairs) {
  absl::StrAppend(s, "\n", intro, ":\n\n| output |");
  for (const char* f : names) absl::StrAppend(s, " ", f, " |");
  *s += "\n| --- |";
  for (size_t k = 0; k < N; ++k) *s += " --- |";
  *s += "\n";
  for (const EvalRow& r : rows) {
    absl::StrAppend(s, "| ", r.name, " |");
    for (size_t k = 0; k < N; ++k)
      absl::StrAppendFormat(s, " %.2f (%d) |", (r.*share)[k], (r.*pairs)[k]);
    *s += "\n";
  }
}

// Each output's share of the gap from `content` to `style` per figure, into
// `shares` (figures whose two clips differ by less than 10% are left out;
// an output without figures counts 0).
template <size_t N>
void AddShares(const std::array<double, N>& content, const std::array<double, N>& style,
               const std::optional<std::array<double, N>>& out,
               std::array<std::vector<double>, N>* shares) {
  for (size_t k = 0; k < N; ++k) {
    const double c = content[k], gap = style[k] - c;
    if (std::abs(gap) < 0.1 * std::max(c, style[k])) continue;
    (*shares)[k].push_back(out ? std::clamp(((*out)[k] - c) / gap, -1.0, 2.0) : 0.0);
  }
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

}  // namespace

absl::StatusOr<PairKind> ParsePairKind(absl::string_view name) {
  if (name == "cross-action") return PairKind::kCrossAction;
  if (name == "same-action") return PairKind::kSameAction;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown pair kind '", name, "': use cross-action or same-action"));
}

absl::StatusOr<EvalSplit> ParseEvalSplit(absl::string_view name) {
  if (name == "all") return EvalSplit::kAll;
  if (name == "validation") return EvalSplit::kValidation;
  if (name == "test") return EvalSplit::kTest;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown split '", name, "': use all, validation or test"));
}

const char* PairKindName(PairKind kind) {
  return kind == PairKind::kSameAction ? "same-action" : "cross-action";
}

const char* EvalSplitName(EvalSplit split) {
  switch (split) {
    case EvalSplit::kValidation:
      return "validation";
    case EvalSplit::kTest:
      return "test";
    case EvalSplit::kAll:
      break;
  }
  return "all";
}

bool InEvalSplit(const std::string& path, EvalSplit split) {
  if (split == EvalSplit::kAll) return true;
  const bool validation = motion::StableHash(FileName(path), 48) % 2 == 0;
  return validation == (split == EvalSplit::kValidation);
}

absl::StatusOr<std::vector<EvalPair>> MakeEvalPairs(const std::vector<std::string>& dirs,
                                                    int per_content, PairKind kind,
                                                    EvalSplit split) {
  absl::StatusOr<motion::DatasetIndex> index = motion::IndexDataset(dirs);
  if (!index.ok()) return index.status();
  const std::vector<const motion::ClipEntry*> test = index->Split(true);
  std::vector<EvalPair> pairs;
  for (const motion::ClipEntry* c : test) {
    if (!InEvalSplit(c->path, split)) continue;
    std::vector<const motion::ClipEntry*> styles;
    for (const motion::ClipEntry* s : test) {
      if (s->label.style == c->label.style) continue;
      // Same action: the same label in the same dataset. Cross-action:
      // another label (a dataset-1 walk is no cross-action pair for a
      // dataset-2 walk, nor a same-action one: the datasets' labels differ).
      const bool cross = s->label.content != c->label.content;
      const bool same = !cross && s->label.dataset == c->label.dataset;
      if (kind == PairKind::kSameAction ? same : cross) styles.push_back(s);
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

absl::StatusOr<EvalReport> Evaluate(const std::vector<EvalModel>& models, const Judges& judges,
                                    const FeatureJudge* features,
                                    const std::vector<motion::Motion>& reference,
                                    const std::vector<EvalPair>& pairs,
                                    const std::function<void(int, int)>& progress,
                                    const Judges* second_judges, const MotionJudge* motion_judge) {
  if (models.empty()) return absl::InvalidArgumentError("no model to evaluate");
  EvalReport report;
  report.second_judges = second_judges != nullptr;
  report.motion_judge = motion_judge != nullptr;
  if (motion_judge) report.motion_judge_trained = motion_judge->trained_accuracy();
  for (const EvalModel& m : models) {
    report.rows.push_back({m.name + ", no post-processing"});
    if (m.postprocess) report.rows.push_back({m.name + ", post-processing full"});
    if (m.style_timing) report.rows.push_back({"content at the style's cadence (no model)"});
  }
  report.identity_row = static_cast<int>(report.rows.size());
  report.rows.push_back({"identity (output = content)"});
  report.rows.push_back({"copy-style (output = style)"});
  const size_t n_rows = report.rows.size();
  std::vector<std::vector<std::vector<double>>> embeddings(n_rows);
  const motion::HumanoidRoles& roles = models[0].model->data().roles;
  // Per row and gait figure: each pair's share of the content-to-style gap.
  std::vector<std::array<std::vector<double>, 5>> gait_shares(n_rows);
  std::vector<std::array<std::vector<double>, 2>> gesture_shares(n_rows);
  int done = 0;
  for (size_t pair = 0; pair < pairs.size(); ++pair) {
    const EvalPair& p = pairs[pair];
    absl::StatusOr<motion::Motion> content = motion::ReadBvhFile(p.content_path);
    if (!content.ok()) return content.status();
    absl::StatusOr<motion::Motion> style = motion::ReadBvhFile(p.style_path);
    if (!style.ok()) return style.status();
    const auto style_label = motion::ParseClipName(p.style_path),
               content_label = motion::ParseClipName(p.content_path);
    if (!style_label || !content_label)
      return absl::InvalidArgumentError("pair without labels: " + p.content_path);
    // Whether `j` judges `out` as the pair's style and content.
    auto verdict = [&](const Judges& j, const motion::Motion& out) -> absl::StatusOr<Verdict> {
      absl::StatusOr<int> s = j.ClassifyStyle(out);
      if (!s.ok()) return s.status();
      absl::StatusOr<int> c = j.ClassifyContent(out);
      if (!c.ok()) return c.status();
      return Verdict{j.styles()[*s], j.contents()[*c], j.styles()[*s] == style_label->style,
                     j.contents()[*c] == content_label->content};
    };
    std::vector<motion::Motion> outputs;
    // Per output: the content clip it is measured against (its feet, its
    // path), at the output's speed; the warped ones live in `warped`.
    std::vector<const motion::Motion*> measured_against;
    std::deque<motion::Motion> warped;
    std::vector<const TransferResult::Contacts*> own_contacts;  // Per output (null: the clip's).
    std::deque<TransferResult::Contacts> kept_contacts;
    std::vector<std::string> movement;  // Per output: MovementNote's example or reason.
    for (const EvalModel& m : models) {
      absl::StatusOr<StyleCode> code = m.model->EncodeStyle(m.own_style ? *content : *style);
      if (!code.ok()) return code.status();
      TransferOptions options(motion::PostProcessMode::kNone);
      if (m.style_timing) options.timing = Timing::kStyle;
      options.movement.library = m.library;
      if (m.label_from_name) options.movement.style_label = style_label->style;
      absl::StatusOr<TransferResult> transferred;
      if (m.stream) {
        std::optional<TransferResult::Contacts> own;
        absl::StatusOr<motion::Motion> streamed = StreamClip(
            *m.model, *content, *code, motion::PostProcessMode::kNone, options.movement, &own);
        if (!streamed.ok()) return streamed.status();
        transferred = TransferResult{};
        transferred->motion = *std::move(streamed);
        transferred->contacts = std::move(own);
      } else {
        transferred = m.model->Transfer(*content, *code, options);
      }
      if (!transferred.ok()) return transferred.status();
      const TransferNote& note = transferred->note;
      const motion::Motion* raw = &transferred->motion;
      if (note.guarded) {
        EvalRow& row = report.rows[outputs.size()];  // This model's raw row.
        ++row.guarded;
        if (note.backed_off) ++row.backed_off_at[note.residual_strength];
      }
      const motion::Motion* timed = &*content;
      if (transferred->warp.applied) {
        EvalRow& row = report.rows[outputs.size()];
        ++row.time_warped;
        row.time_warp_ratio += transferred->warp.ratio;
        timed = &warped.emplace_back(motion::TimeWarp(*content, transferred->warp.ratio));
      }
      const TransferResult::Contacts* planted =
          transferred->contacts ? &kept_contacts.emplace_back(*transferred->contacts) : nullptr;
      if (transferred->movement.applied) {
        EvalRow& row = report.rows[outputs.size()];
        ++row.moved;
        const bool from_library = transferred->movement.example.rfind("style clip", 0) != 0;
        row.moved_from_library += from_library;
        if (m.postprocess) {
          ++report.rows[outputs.size() + 1].moved;
          report.rows[outputs.size() + 1].moved_from_library += from_library;
        }
      }
      const MovementNote& mv = transferred->movement;
      const std::string moved_by =
          mv.applied ? absl::StrFormat("%s (%s, fit %.3f)", mv.example, mv.kind, mv.cost)
                     : mv.reason;
      outputs.push_back(*raw);
      measured_against.push_back(timed);
      own_contacts.push_back(planted);
      movement.push_back(moved_by);
      if (m.postprocess) {
        // Post-processed as the model would: on the output's own contacts
        // when its steps are its own.
        motion::PostProcessParams params;
        params.contact_spans = planted;
        absl::StatusOr<motion::Motion> full =
            m.stream ? StreamClip(*m.model, *content, *code, motion::PostProcessMode::kFull,
                                  options.movement)
                     : motion::PostProcess(*raw, planted ? *raw : *timed, roles,
                                           motion::PostProcessMode::kFull, params);
        if (!full.ok()) return full.status();
        outputs.push_back(*std::move(full));
        measured_against.push_back(timed);
        own_contacts.push_back(planted);
        movement.push_back(moved_by);
      }
      if (m.style_timing) {
        outputs.push_back(*timed);
        measured_against.push_back(timed);
        own_contacts.push_back(nullptr);
      }
    }
    outputs.push_back(*content);
    outputs.push_back(*style);
    // Copy-style has another length: its feet are measured against itself.
    measured_against.push_back(&*content);
    measured_against.push_back(&*style);
    std::optional<FeatureMap> content_features, style_features;
    if (features) {
      absl::StatusOr<FeatureMap> c = features->Features(*content), s = features->Features(*style);
      if (!c.ok()) return c.status();
      if (!s.ok()) return s.status();
      content_features = *std::move(c);
      style_features = *std::move(s);
    }
    const std::optional<std::array<double, 5>> content_gait = GaitFigures(*content, roles),
                                                style_gait = GaitFigures(*style, roles);
    const std::optional<std::array<double, 2>> content_gesture = GestureFigures(*content, roles),
                                               style_gesture = GestureFigures(*style, roles);
    for (size_t r = 0; r < n_rows; ++r) {
      const motion::Motion& out = outputs[r];
      // The baselines' rows are the two clips themselves. An output that
      // stopped stepping (or started) keeps nothing of either clip's figures.
      if (content_gesture && style_gesture) {
        AddShares(*content_gesture, *style_gesture,
                  r + 2 == n_rows   ? content_gesture
                  : r + 1 == n_rows ? style_gesture
                                    : GestureFigures(out, roles),
                  &gesture_shares[r]);
      }
      if (content_gait && style_gait) {
        AddShares(*content_gait, *style_gait,
                  r + 2 == n_rows   ? content_gait
                  : r + 1 == n_rows ? style_gait
                                    : GaitFigures(out, roles),
                  &gait_shares[r]);
      }
      absl::StatusOr<Verdict> v = verdict(judges, out);
      if (!v.ok()) return v.status();
      EvalRow& row = report.rows[r];
      EvalVerdict judged{static_cast<int>(pair),
                         static_cast<int>(r),
                         v->style,
                         v->content,
                         "",
                         r < movement.size() ? movement[r] : ""};
      row.style_accuracy += v->style_right;
      row.content_accuracy += v->content_right;
      row.source_style += v->style == content_label->style;
      if (motion_judge) {
        absl::StatusOr<int> m = motion_judge->ClassifyStyle(out);
        if (!m.ok()) return m.status();
        judged.motion_style = motion_judge->styles()[*m];
        row.motion_style_accuracy += judged.motion_style == style_label->style;
        row.motion_source_style += judged.motion_style == content_label->style;
      }
      report.verdicts.push_back(std::move(judged));
      if (second_judges) {
        absl::StatusOr<Verdict> w = verdict(*second_judges, out);
        if (!w.ok()) return w.status();
        row.second_style_accuracy += w->style_right;
        row.second_content_accuracy += w->content_right;
        row.content_by_both += v->content_right && w->content_right;
      }
      const motion::Motion& planted = *measured_against[r];
      row.foot_skating += motion::FootSkating(out, planted, roles);
      row.own_skating += r < own_contacts.size() && own_contacts[r] != nullptr
                             ? motion::FootSkatingOnSpans(out, *own_contacts[r], roles)
                             : motion::FootSkating(out, planted, roles);
      row.below_floor = std::max(row.below_floor, BelowFloor(out, planted, roles));
      row.foot_height_error += motion::FootHeightError(out, planted, roles);
      row.bone_length_error += motion::BoneLengthError(out, roles);
      row.jitter += motion::Jitter(out);
      // The path against the content's (copy-style's too: how far it strays).
      row.trajectory_error +=
          motion::TrajectoryError(out, r + 1 == n_rows ? *content : planted, roles);
      row.euler_discontinuities += motion::EulerDiscontinuities(out);
      if (features) {
        absl::StatusOr<FeatureMap> f = features->Features(out);
        if (!f.ok()) return f.status();
        row.content_distance += ContentDistance(*f, *content_features);
        const double d_style = StyleDistance(*f, *style_features);
        const double d_content = StyleDistance(*f, *content_features);
        row.style_distance += d_style;
        const double ratio = d_style + d_content > 0 ? d_style / (d_style + d_content) : 0.5;
        row.d_s += ratio;
        row.d_c += 1 - ratio;
        embeddings[r].push_back(Embedding(*f));
      }
      ++row.pairs;
    }
    if (progress) progress(++done, static_cast<int>(pairs.size()));
  }
  std::vector<std::vector<double>> real;
  if (features) {
    for (const motion::Motion& clip : reference) {
      absl::StatusOr<FeatureMap> f = features->Features(clip);
      if (!f.ok()) return f.status();
      real.push_back(Embedding(*f));
    }
    report.reference_clips = static_cast<int>(real.size());
    if (real.size() >= 2) report.real_diversity = Diversity(real, 1000, 7);
  }
  for (size_t r = 0; r < n_rows; ++r) {
    EvalRow& row = report.rows[r];
    if (row.time_warped > 0) row.time_warp_ratio /= row.time_warped;
    row.style_accuracy /= row.pairs;
    row.content_accuracy /= row.pairs;
    row.second_style_accuracy /= row.pairs;
    row.second_content_accuracy /= row.pairs;
    row.content_by_both /= row.pairs;
    row.source_style /= row.pairs;
    row.motion_style_accuracy /= row.pairs;
    row.motion_source_style /= row.pairs;
    row.foot_skating /= row.pairs;
    row.own_skating /= row.pairs;
    row.foot_height_error /= row.pairs;
    row.bone_length_error /= row.pairs;
    row.jitter /= row.pairs;
    row.content_distance /= row.pairs;
    row.style_distance /= row.pairs;
    row.d_s /= row.pairs;
    row.d_c /= row.pairs;
    row.trajectory_error /= row.pairs;
    for (int k = 0; k < 5; ++k) {
      row.gait_toward_style[k] = Median(gait_shares[r][k]);
      row.gait_pairs[k] = static_cast<int>(gait_shares[r][k].size());
    }
    for (int k = 0; k < 2; ++k) {
      row.gesture_toward_style[k] = Median(gesture_shares[r][k]);
      row.gesture_pairs[k] = static_cast<int>(gesture_shares[r][k].size());
    }
    if (features && real.size() >= 2 && embeddings[r].size() >= 2) {
      row.fmd = FrechetDistance(embeddings[r], real);
      std::tie(row.kid, row.kid_std) = KernelInceptionDistance(embeddings[r], real, 10, 100, 11);
      row.diversity = Diversity(embeddings[r], 1000, 7);
    }
  }
  return report;
}

namespace {

// A CSV field, quoted when it holds a comma, a quote or a line break.
std::string CsvField(const std::string& v) {
  if (v.find_first_of(",\"\n") == std::string::npos) return v;
  std::string q = "\"";
  for (char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

std::string EvalReport::VerdictsCsv(const std::vector<EvalPair>& pairs) const {
  std::string s =
      "content_bvh,style_bvh,output,style,judged_style,content,judged_content,movement\n";
  for (const EvalVerdict& v : verdicts) {
    const EvalPair& p = pairs[v.pair];
    const auto style = motion::ParseClipName(p.style_path);
    const auto content = motion::ParseClipName(p.content_path);
    const std::vector<std::string> fields = {p.content_path,   p.style_path,
                                             rows[v.row].name, style ? style->style : "",
                                             v.style,          content ? content->content : "",
                                             v.content,        v.movement};
    for (size_t i = 0; i < fields.size(); ++i)
      absl::StrAppend(&s, i ? "," : "", CsvField(fields[i]));
    s += "\n";
  }
  return s;
}

std::string EvalReport::ByDatasetMarkdown(const std::vector<EvalPair>& pairs) const {
  std::vector<std::optional<motion::ClipLabel>> style(pairs.size()), content(pairs.size());
  std::vector<std::string> datasets;
  for (size_t i = 0; i < pairs.size(); ++i) {
    content[i] = motion::ParseClipName(pairs[i].content_path);
    style[i] = motion::ParseClipName(pairs[i].style_path);
    if (content[i] && style[i]) datasets.push_back(content[i]->dataset);
  }
  std::sort(datasets.begin(), datasets.end());
  datasets.erase(std::unique(datasets.begin(), datasets.end()), datasets.end());
  // Groups: each content dataset, then one dataset and two.
  std::vector<std::string> groups;
  for (const std::string& d : datasets) groups.push_back("content from " + d);
  const int one = static_cast<int>(groups.size()), two = one + 1;
  groups.push_back("both clips from one dataset");
  groups.push_back("from two datasets");
  std::vector<std::vector<int>> group_of(pairs.size());
  std::vector<int> pairs_in(groups.size(), 0);
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!content[i] || !style[i]) continue;
    const auto d = std::find(datasets.begin(), datasets.end(), content[i]->dataset);
    group_of[i] = {static_cast<int>(d - datasets.begin()),
                   content[i]->dataset == style[i]->dataset ? one : two};
    for (int g : group_of[i]) ++pairs_in[g];
  }
  // [row][group]: pairs whose judged style / content is right.
  std::vector<std::vector<int>> style_right(rows.size(), std::vector<int>(groups.size(), 0));
  std::vector<std::vector<int>> content_right = style_right;
  for (const EvalVerdict& v : verdicts) {
    for (int g : group_of[v.pair]) {
      style_right[v.row][g] += v.style == style[v.pair]->style;
      content_right[v.row][g] += v.content == content[v.pair]->content;
    }
  }
  std::string s = "| output |";
  for (size_t g = 0; g < groups.size(); ++g)
    absl::StrAppendFormat(&s, " %s (%d pairs) |", groups[g], pairs_in[g]);
  s += "\n| --- |";
  for (size_t g = 0; g < groups.size(); ++g) s += " --- |";
  s += "\n";
  for (size_t r = 0; r < rows.size(); ++r) {
    absl::StrAppend(&s, "| ", rows[r].name, " |");
    for (size_t g = 0; g < groups.size(); ++g) {
      if (pairs_in[g] == 0) {
        s += " - |";
        continue;
      }
      absl::StrAppendFormat(&s, " %.3f / %.3f |", double(style_right[r][g]) / pairs_in[g],
                            double(content_right[r][g]) / pairs_in[g]);
    }
    s += "\n";
  }
  return s;
}

std::string EvalReport::ByStyleMarkdown(const std::vector<EvalPair>& pairs) const {
  // style -> row -> (pose hits, motion hits, pairs)
  std::map<std::string, std::vector<std::array<int, 3>>> hits;
  for (const EvalVerdict& v : verdicts) {
    const std::optional<motion::ClipLabel> want = motion::ParseClipName(pairs[v.pair].style_path);
    if (!want) continue;
    auto& per_row = hits[want->style];
    per_row.resize(rows.size(), {0, 0, 0});
    per_row[v.row][0] += v.style == want->style;
    per_row[v.row][1] += v.motion_style == want->style;
    per_row[v.row][2] += 1;
  }
  std::string s = "| output |";
  for (const auto& [style, unused] : hits) absl::StrAppend(&s, " ", style, " |");
  s += "\n| --- |";
  for (size_t i = 0; i < hits.size(); ++i) s += " --- |";
  s += "\n";
  for (size_t r = 0; r < rows.size(); ++r) {
    absl::StrAppend(&s, "| ", rows[r].name, " |");
    for (const auto& [style, per_row] : hits) {
      const auto& h = per_row[r];
      if (h[2] == 0) {
        s += " - |";
      } else if (motion_judge) {
        absl::StrAppendFormat(&s, " %.2f / %.2f |", double(h[0]) / h[2], double(h[1]) / h[2]);
      } else {
        absl::StrAppendFormat(&s, " %.2f |", double(h[0]) / h[2]);
      }
    }
    s += "\n";
  }
  return s;
}

std::string EvalReport::Markdown() const {
  std::string s =
      "| output | pairs | style accuracy | content accuracy | FMD | KID | diversity | content "
      "distance | style distance | D_S | D_C |\n"
      "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const EvalRow& r : rows) {
    absl::StrAppendFormat(
        &s, "| %s | %d | %.3f | %.3f | %.2f | %.3f +- %.3f | %.2f | %.3f | %.4f | %.3f | %.3f |\n",
        r.name, r.pairs, r.style_accuracy, r.content_accuracy, r.fmd, r.kid, r.kid_std, r.diversity,
        r.content_distance, r.style_distance, r.d_s, r.d_c);
  }
  if (reference_clips > 0) {
    absl::StrAppendFormat(
        &s,
        "\nFMD and KID against %d real clips (the feature judge's hidden layer: "
        "per-channel mean and standard deviation over time); real clips' own "
        "diversity: %.2f. D_S and D_C: paper 004's style similarity ratios of the Gram "
        "distances to the style and the content clip (low D_S: the output's "
        "style is the style clip's).\n",
        reference_clips, real_diversity);
  }
  for (const EvalRow& r : rows) {
    if (r.guarded == 0) continue;
    int backed_off = 0;
    std::string where;
    for (const auto& [strength, n] : r.backed_off_at) {
      backed_off += n;
      absl::StrAppendFormat(&where, "%s%d at strength %g", where.empty() ? "" : ", ", n, strength);
    }
    absl::StrAppendFormat(&s,
                          "\nContent guard (%s): of %d transfers, %d kept the configured form; "
                          "the residual form was returned for %d (%s; the smallest strength also "
                          "when no form kept the action).\n",
                          r.name, r.guarded, r.guarded - backed_off, backed_off,
                          where.empty() ? "none" : where);
  }
  for (const EvalRow& r : rows) {
    if (r.time_warped == 0) continue;
    absl::StrAppendFormat(&s,
                          "\nStyle timing (%s): %d of %d transfers time-warped to the style "
                          "clip's cadence, mean duration ratio %.2f (the others keep the "
                          "content's timing: a clip without a cadence, or one that steps against "
                          "one that does not); the feet and path are measured against the "
                          "content warped alike.\n",
                          r.name, r.time_warped, r.pairs, r.time_warp_ratio);
  }
  if (second_judges) {
    s +=
        "\nSecond judges (the same outputs):\n\n"
        "| output | style accuracy | content accuracy | content kept by both judges | by either |\n"
        "| --- | --- | --- | --- | --- |\n";
    for (const EvalRow& r : rows) {
      absl::StrAppendFormat(&s, "| %s | %.3f | %.3f | %.3f | %.3f |\n", r.name,
                            r.second_style_accuracy, r.second_content_accuracy, r.content_by_both,
                            r.ContentByEither());
    }
  }
  if (motion_judge) {
    absl::StrAppendFormat(
        &s,
        "\nStyle in the motion: the motion-only judge reads joint velocities, no pose "
        "(held-out real clips: %.3f; the same clips frozen on one frame: %.3f; a constant "
        "verdict would score %.3f). 'As the content's style': the output still reads as the style "
        "the "
        "content clip was performed in.\n\n"
        "| output | pose judge: style | pose judge: as the content's style | motion judge: "
        "style | motion judge: as the content's style |\n"
        "| --- | --- | --- | --- | --- |\n",
        motion_judge_trained.held_out, motion_judge_trained.frozen, motion_judge_trained.chance);
    for (const EvalRow& r : rows) {
      absl::StrAppendFormat(&s, "| %s | %.3f | %.3f | %.3f | %.3f |\n", r.name, r.style_accuracy,
                            r.source_style, r.motion_style_accuracy, r.motion_source_style);
    }
  }
  for (const EvalRow& r : rows) {
    if (r.moved == 0) continue;
    absl::StrAppendFormat(&s,
                          "\nMovement from examples (%s): %d of %d transfers took their movement "
                          "from an example (%d from the style clip, %d from a library take); the "
                          "others kept the network's.\n",
                          r.name, r.moved, r.pairs, r.moved - r.moved_from_library,
                          r.moved_from_library);
  }
  if (!rows.empty() && rows[0].gait_pairs[1] > 0) {
    AppendShares(&s,
                 "Gait (stylus-tool gait's figures), over the pairs whose content and style clips "
                 "both step: how far each output's figure moved from the content clip's towards "
                 "the style clip's (median share of the gap: 0 the content's, 1 the style's; over "
                 "the pairs whose clips differ by 10% or more in it; pairs in brackets)",
                 kGaitFigures, rows, &EvalRow::gait_toward_style, &EvalRow::gait_pairs);
  }
  if (!rows.empty() && (rows[0].gesture_pairs[0] > 0 || rows[0].gesture_pairs[1] > 0)) {
    AppendShares(&s,
                 "Gestures, over the pairs whose content and style clips both do not step: how "
                 "far each output's hand speed (95th percentile) and hand reach (vertical "
                 "travel) moved from the content clip's towards the style clip's (median share "
                 "of the gap, as above)",
                 kGestureFigures, rows, &EvalRow::gesture_toward_style, &EvalRow::gesture_pairs);
  }
  s += "\nKinematics (means over pairs; feet measured where the content clip's feet are "
       "planted, copy-style against the style clip itself; 'own contacts': where the output "
       "planted its feet when its steps are its own, else the same; 'below floor': the deepest "
       "any foot went under the floor, leg lengths):\n\n"
       "| output | foot skating (units/s) | on its own contacts | below floor | foot height error "
       "(units) | bone length error | jitter (units/s^3) | Euler discontinuities | trajectory "
       "error (units) |\n"
       "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const EvalRow& r : rows) {
    absl::StrAppendFormat(&s, "| %s | %.2f | %.2f | %.3f | %.2f | %.4f%% | %.0f | %d | %.2f |\n",
                          r.name, r.foot_skating, r.own_skating, r.below_floor, r.foot_height_error,
                          100 * r.bone_length_error, r.jitter, r.euler_discontinuities,
                          r.trajectory_error);
  }
  if (identity_row >= 2) {
    const EvalRow &full = rows[1], &real = rows[identity_row];
    absl::StrAppendFormat(
        &s,
        "\n%s against real data (identity row): foot skating %.2fx on its own contacts "
        "(target <= 1.2x), "
        "jitter %.2fx (target <= 1.5x), bone length error %.4f%% (target < 0.1%%), Euler "
        "discontinuities %d (real data: %d).\n",
        full.name, full.own_skating / std::max(real.own_skating, 1e-9),
        full.jitter / std::max(real.jitter, 1e-9), 100 * full.bone_length_error,
        full.euler_discontinuities, real.euler_discontinuities);
  }
  return s;
}

}  // namespace stylus::model
