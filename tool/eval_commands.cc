// train-judges and eval.
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "eval/evaluation.h"
#include "eval/feature_judge.h"
#include "eval/judges.h"
#include "eval/motion_judge.h"
#include "model/package.h"
#include "model/runtime.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/files.h"
#include "tool/charts.h"
#include "tool/cli_support.h"
#include "tool/model_spec.h"
#include "tool/part_swap.h"
#include "tool/style_map.h"

namespace stylus::tool {

int TrainJudges(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool train-judges --data DIR... --out models/judges/VERSION\n"
      "         [--iters 3000] [--batch 32] [--dae-iters 3000] [--dae-only] [--seed S]\n"
      "         [--random-starts] [--swap-parts P] [--threads N] [--motion-only]\n\n"
      "Trains, on the labelled training split of DIR, a style classifier and a\n"
      "content classifier (class-balanced batches) and reports their clip-level\n"
      "accuracy on the held-out split; then the motion-only style judge, which\n"
      "sees joint velocities and no pose, and reports its accuracy on held-out\n"
      "clips and on the same clips frozen on one frame (near chance: it reads no\n"
      "pose); then the feature judge, a denoising autoencoder (no labels) whose\n"
      "hidden layer `eval` reads for FMD, KID, diversity and the content and\n"
      "style distances, and reports its held-out denoising error.\n"
      "--dae-only adds the feature judge to existing judges, --motion-only the\n"
      "motion-only style judge.\n"
      "--random-starts draws the classifiers' training windows anywhere in their\n"
      "clips instead of on the hop grid (the grid never reaches a clip's last\n"
      "frames, which evaluation shows them).\n"
      "--swap-parts P gives each drawn window, with probability P, one body part\n"
      "(legs, torso or an arm) of another window with the same label, so the\n"
      "content judge reads an action from the body part that performs it rather\n"
      "than from one take's way of moving the rest (see judge --swap-test).\n";
  int code = 0;
  auto args =
      ParseOrExit("train-judges", argv,
                  {{"data", "out", "iters", "batch", "seed", "threads", "dae-iters", "swap-parts"},
                   {"dae-only", "random-starts", "motion-only"}},
                  kHelp, &code);
  if (!args) return code;
  model::JudgeTrainOptions o;
  o.data = args->All("data");
  o.out = args->Get("out");
  if (o.data.empty() || o.out.empty()) {
    std::fprintf(stderr, "stylus-tool train-judges: --data and --out are required\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<int> iters = args->GetInt("iters", o.iterations),
                      batch = args->GetInt("batch", o.batch);
  absl::StatusOr<int> seed = args->GetInt("seed", 1), threads = args->GetInt("threads", 0),
                      dae_iters = args->GetInt("dae-iters", 3000);
  for (const absl::Status& s :
       {iters.status(), batch.status(), seed.status(), threads.status(), dae_iters.status()}) {
    if (!s.ok()) return Fail("train-judges", s);
  }
  o.iterations = *iters, o.batch = *batch, o.seed = *seed;
  o.random_starts = args->switches.count("random-starts") > 0;
  absl::StatusOr<double> swap = args->GetDouble("swap-parts", 0);
  if (!swap.ok()) return Fail("train-judges", swap.status());
  if (*swap < 0 || *swap > 1) {
    return Fail("train-judges", absl::InvalidArgumentError("--swap-parts must be in [0, 1]"));
  }
  o.swap_parts = *swap;
  model::SetComputeThreads(*threads);
  const bool dae_only = args->switches.count("dae-only") > 0,
             motion_only = args->switches.count("motion-only") > 0;
  if (dae_only && motion_only) {
    return Fail("train-judges",
                absl::InvalidArgumentError("--dae-only and --motion-only exclude each other"));
  }
  if (!dae_only && !motion_only) {
    absl::StatusOr<model::JudgeAccuracy> acc = model::TrainJudges(o);
    if (!acc.ok()) return Fail("train-judges", acc.status());
    absl::PrintF("held-out clips: %d\nstyle accuracy: %.3f\ncontent accuracy: %.3f\n", acc->clips,
                 acc->style, acc->content);
  }
  if (!dae_only) {
    absl::StatusOr<model::MotionJudgeAccuracy> motion = model::TrainMotionJudge(o);
    if (!motion.ok()) return Fail("train-judges", motion.status());
    absl::PrintF(
        "motion-only style judge: held-out accuracy %.3f; the same clips frozen %.3f (chance "
        "%.3f)\n",
        motion->held_out, motion->frozen, motion->chance);
    if (motion_only) {
      absl::PrintF("motion-only judge written to %s\n", o.out);
      return 0;
    }
  }
  absl::StatusOr<model::DaeTrainResult> dae = model::TrainFeatureJudge(
      o.data, o.out, *dae_iters, o.seed,
      [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); });
  if (!dae.ok()) return Fail("train-judges", dae.status());
  absl::PrintF(
      "feature judge: held-out denoising error %.4f (the corrupted input's: %.4f, %d clips)\n"
      "judges written to %s\n",
      dae->denoised_mse, dae->noisy_mse, dae->clips, o.out);
  return 0;
}

namespace {

// "label 0.93, other 0.05": the judge's most likely labels, best first.
std::string TopLabels(const std::vector<std::string>& labels, const std::vector<double>& p,
                      int count) {
  std::vector<int> order(p.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return p[a] > p[b]; });
  std::string out;
  for (int k = 0; k < count && k < static_cast<int>(order.size()); ++k) {
    absl::StrAppendFormat(&out, "%s%s %.3f", k ? ", " : "", labels[order[k]], p[order[k]]);
  }
  return out;
}

// judge --swap-test.
int JudgeSwapTest(const Args& args, const char* help) {
  if (args.Get("judges").empty() || args.All("data").empty() || !args.positional.empty()) {
    std::fprintf(stderr,
                 "stylus-tool judge: --swap-test takes --judges and --data, and no clips\n\n%s",
                 help);
    return 2;
  }
  absl::StatusOr<std::unique_ptr<model::Judges>> judges = model::Judges::Load(args.Get("judges"));
  if (!judges.ok()) return Fail("judge", judges.status());
  absl::StatusOr<model::SwapTestReport> report =
      model::RunSwapTest(**judges, DataSources(args), [](int done, int total) {
        if (done % 10 == 0 || done == total) {
          std::fprintf(stderr, "\rswap test: %d/%d held-out clips", done, total);
          if (done == total) std::fprintf(stderr, "\n");
        }
      });
  if (!report.ok()) return Fail("judge", report.status());
  const std::string markdown = report->Markdown();
  absl::PrintF("%s", markdown);
  if (!args.Get("out").empty()) {
    if (absl::Status s = motion::WriteFileAtomically(args.Get("out"), markdown); !s.ok()) {
      return Fail("judge", s);
    }
  }
  return 0;
}

}  // namespace

int Judge(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool judge --judges DIR [--top 3] CLIP.bvh...\n"
      "       stylus-tool judge --judges DIR --swap-test --data DIR... [--out report.md]\n\n"
      "Prints what the judges (stylus-tool train-judges) read in each clip: its\n"
      "most likely styles and contents with their probabilities (the softmax of\n"
      "the clip's mean logits), best first, one line per clip. The verdicts are\n"
      "the ones eval counts; the runners-up show how close a call was (a raised\n"
      "hand read as a wave). When DIR has a motion-only style judge, its verdict\n"
      "follows.\n"
      "--swap-test checks whether the content judge reads an action from the body\n"
      "part that performs it: each held-out clip of DIR gets the legs, the torso\n"
      "or an arm of another real clip (the same action in another style, then\n"
      "another action in the same style) and the content verdicts are counted\n"
      "(Markdown on stdout, and in --out).\n";
  int code = 0;
  auto args =
      ParseOrExit("judge", argv, {{"judges", "top", "data", "out"}, {"swap-test"}}, kHelp, &code);
  if (!args) return code;
  if (args->switches.count("swap-test")) return JudgeSwapTest(*args, kHelp);
  if (args->Get("judges").empty() || args->positional.empty()) {
    std::fprintf(stderr, "stylus-tool judge: --judges and at least one clip are required\n\n%s",
                 kHelp);
    return 2;
  }
  absl::StatusOr<int> top = args->GetInt("top", 3);
  if (!top.ok()) return Fail("judge", top.status());
  if (*top < 1) return Fail("judge", absl::InvalidArgumentError("--top must be at least 1"));
  absl::StatusOr<std::unique_ptr<model::Judges>> judges = model::Judges::Load(args->Get("judges"));
  if (!judges.ok()) return Fail("judge", judges.status());
  absl::StatusOr<std::unique_ptr<model::MotionJudge>> motion_judge =
      model::MotionJudge::Load(args->Get("judges"));
  if (!motion_judge.ok() && motion_judge.status().code() != absl::StatusCode::kNotFound) {
    return Fail("judge", motion_judge.status());
  }
  for (const std::string& path : args->positional) {
    absl::StatusOr<motion::Motion> clip = motion::ReadBvhFile(path);
    if (!clip.ok()) return Fail("judge", clip.status());
    absl::StatusOr<std::vector<double>> style = (*judges)->StyleProbabilities(*clip);
    absl::StatusOr<std::vector<double>> content = (*judges)->ContentProbabilities(*clip);
    for (const auto* p : {&style, &content}) {
      if (!p->ok())
        return Fail("judge", absl::Status(p->status().code(),
                                          absl::StrCat(path, ": ", p->status().message())));
    }
    std::string motion_style;
    if (motion_judge.ok()) {
      absl::StatusOr<std::vector<double>> p = (*motion_judge)->StyleProbabilities(*clip);
      if (!p.ok()) return Fail("judge", p.status());
      motion_style = "\tmotion-only style: " + TopLabels((*motion_judge)->styles(), *p, *top);
    }
    absl::PrintF("%s\tstyle: %s\tcontent: %s%s\n", path,
                 TopLabels((*judges)->styles(), *style, *top),
                 TopLabels((*judges)->contents(), *content, *top), motion_style);
  }
  return 0;
}

int Eval(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool eval --model DIR --judges DIR --data DIR... --out report.md\n"
      "         [--ablation LABEL=DIR]... [--pairs-per-content 3] [--threads N]\n"
      "         [--verdicts verdicts.csv] [--second-judges DIR] [--own-style]\n"
      "         [--timing-style] [--pair-kind cross-action|same-action|all]\n"
      "         [--split all|validation|test] [--library DIR [--library-label name|code]]\n\n"
      "Transfers deterministic held-out pairs (content clip x style clip of another\n"
      "content and another style) and reports, as Markdown: style and content\n"
      "recognition accuracy (by the judges); FMD and KID against every clip of\n"
      "DIR, diversity, content and style (Gram) distances (by the feature judge,\n"
      "when the judges have one); foot skating, foot height error, bone length\n"
      "error, jitter and Euler discontinuities. Rows: the model without and with\n"
      "post-processing, each --ablation model (without), and the identity and\n"
      "copy-style baselines; then each row's style and content accuracy over the\n"
      "pairs whose content clip is from each dataset, and over pairs within one\n"
      "dataset and across two. Any family; a model's DIR may end in :KEY=VALUE\n"
      "inference keys (docs/config.md), e.g. models/cyclic/v2:kc_iters=100.\n"
      "--verdicts writes, per pair and output, the judged style and content\n"
      "next to the wanted ones (CSV).\n"
      "--second-judges DIR judges every output a second time (e.g. judges trained\n"
      "with --random-starts) and adds their accuracies and the share of pairs\n"
      "whose content both sets, or either, recognized.\n"
      "--own-style adds a row of the model restyling each content clip with its\n"
      "own style: what it keeps of a clip it should give back unchanged (its\n"
      "ceiling on content accuracy).\n"
      "--timing-style adds the model's transfers with the style clip's cadence\n"
      "(timing = style: time-warped; feet and path measured against the content\n"
      "warped alike), without and with post-processing, and the content itself\n"
      "played at the style's cadence (what the warp alone does).\n"
      "--pair-kind same-action pairs each content clip with held-out takes of the\n"
      "same action in other styles (default: cross-action, another action); all\n"
      "reports same-action pairs, then cross-action pairs without and (with\n"
      "--library) with the library, in one report.\n"
      "--split validation|test keeps the content clips of one half of the held-out\n"
      "split (a stable hash of the file name): choose settings on validation,\n"
      "report on test.\n"
      "--library DIR gives packages with movement from examples a style library:\n"
      "the held-out takes under DIR (takes in the training split of --data, the\n"
      "judges' takes, are left out, so a library and its judges never share a\n"
      "take). --library-label code finds the library's style by the style code\n"
      "(as the server does) instead of the style clip's name.\n"
      "--stream sends each content clip through a stream, one frame per push as a\n"
      "stage would, post-processed by the stream (live packages: the causal\n"
      "network and movement from examples within the look-ahead).\n";
  int code = 0;
  auto args =
      ParseOrExit("eval", argv,
                  {{"model", "judges", "data", "out", "pairs-per-content", "threads", "ablation",
                    "verdicts", "second-judges", "pair-kind", "split", "library", "library-label"},
                   {"own-style", "timing-style", "stream"}},
                  kHelp, &code);
  if (!args) return code;
  if (!args->Has("model") || !args->Has("judges") || !args->Has("data") || !args->Has("out")) {
    std::fprintf(stderr, "stylus-tool eval: --model, --judges, --data and --out are required\n\n%s",
                 kHelp);
    return 2;
  }
  absl::StatusOr<int> per = args->GetInt("pairs-per-content", 3),
                      threads = args->GetInt("threads", 0);
  if (!per.ok()) return Fail("eval", per.status());
  if (!threads.ok()) return Fail("eval", threads.status());
  model::SetComputeThreads(*threads);
  auto loaded = LoadModelSpec(args->Get("model"));
  if (!loaded.ok()) return Fail("eval", loaded.status());
  // Shared: streams (--stream) hold their model.
  const std::shared_ptr<model::StyleModel> m = *std::move(loaded);
  auto judges = model::Judges::Load(args->Get("judges"));
  if (!judges.ok()) return Fail("eval", judges.status());
  std::unique_ptr<model::Judges> second;
  if (args->Has("second-judges")) {
    auto j = model::Judges::Load(args->Get("second-judges"));
    if (!j.ok()) return Fail("eval", j.status());
    second = *std::move(j);
  }
  std::vector<model::EvalModel> models = {{"model", m.get(), true}};
  std::vector<std::unique_ptr<model::StyleModel>> ablations;
  for (const std::string& spec : args->All("ablation")) {
    const size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0) {
      return Fail("eval",
                  absl::InvalidArgumentError("--ablation wants LABEL=DIR, got '" + spec + "'"));
    }
    auto a = LoadModelSpec(spec.substr(eq + 1));
    if (!a.ok()) return Fail("eval", a.status());
    ablations.push_back(*std::move(a));
    models.push_back({spec.substr(0, eq), ablations.back().get(), false});
  }
  if (args->switches.count("own-style")) {
    models.push_back({"model with its own style", m.get(), false, /*own_style=*/true});
  }
  if (args->switches.count("timing-style")) {
    models.push_back({"model, style timing", m.get(), /*postprocess=*/true, /*own_style=*/false,
                      /*style_timing=*/true});
  }
  std::unique_ptr<model::FeatureJudge> features;
  std::vector<motion::Motion> reference;
  if (auto f = model::FeatureJudge::Load(args->Get("judges")); f.ok()) {
    features = *std::move(f);
    auto index = motion::IndexDataset(args->All("data"));
    if (!index.ok()) return Fail("eval", index.status());
    for (const motion::ClipEntry& c : index->clips) {
      auto clip = motion::ReadBvhFile(c.path);
      if (!clip.ok()) return Fail("eval", clip.status());
      reference.push_back(*std::move(clip));
    }
  } else {
    std::fprintf(stderr,
                 "stylus-tool eval: no feature judge (%s); FMD, KID, diversity and the "
                 "distances are left at 0\n",
                 std::string(f.status().message()).c_str());
  }
  std::unique_ptr<model::MotionJudge> motion_judge;
  if (auto j = model::MotionJudge::Load(args->Get("judges")); j.ok()) {
    motion_judge = *std::move(j);
  } else if (j.status().code() == absl::StatusCode::kNotFound) {
    std::fprintf(stderr, "stylus-tool eval: no motion-only judge (%s)\n",
                 std::string(j.status().message()).c_str());
  } else {
    return Fail("eval", j.status());
  }
  // --pair-kind all: the main report on same-action pairs, then sections on
  // cross-action pairs without and (with --library) with the library.
  const bool all_kinds = args->Get("pair-kind") == "all";
  auto kind = all_kinds ? absl::StatusOr<model::PairKind>(model::PairKind::kSameAction)
                        : model::ParsePairKind(args->Get("pair-kind", "cross-action"));
  if (!kind.ok()) return Fail("eval", kind.status());
  auto split = model::ParseEvalSplit(args->Get("split", "all"));
  if (!split.ok()) return Fail("eval", split.status());
  std::unique_ptr<model::StyleLibrary> library;
  if (args->Has("library")) {
    // The judges' takes (the training split of --data) stay out of it.
    auto index = motion::IndexDataset(args->All("data"));
    if (!index.ok()) return Fail("eval", index.status());
    std::vector<std::string> judged;
    for (const motion::ClipEntry* c : index->Split(false)) {
      judged.push_back(std::filesystem::path(c->path).filename().string());
    }
    auto lib = model::StyleLibrary::Load(args->Get("library"), "", judged);
    if (!lib.ok()) return Fail("eval", lib.status());
    library = *std::move(lib);
    std::fprintf(stderr, "stylus-tool eval: style library of %zu held-out takes\n",
                 library->takes().size());
  }
  const std::string label_by = args->Get("library-label", "name");
  if (label_by != "name" && label_by != "code") {
    return Fail("eval", absl::InvalidArgumentError("--library-label is 'name' or 'code'"));
  }
  for (model::EvalModel& em : models) {
    em.stream = args->switches.count("stream") > 0;
    em.library = library.get();
    em.label_from_name = label_by == "name";
  }
  // Every model over `pairs`, with progress on stderr.
  auto evaluate = [&](const std::vector<model::EvalPair>& pairs) {
    auto r = model::Evaluate(
        models, **judges, features.get(), reference, pairs,
        [](int done, int total) {
          if (done % 20 == 0 || done == total)
            std::fprintf(stderr, "\revaluated %d/%d pairs", done, total);
        },
        second.get(), motion_judge.get());
    std::fprintf(stderr, "\n");
    return r;
  };
  auto pairs = model::MakeEvalPairs(args->All("data"), *per, *kind, *split);
  if (!pairs.ok()) return Fail("eval", pairs.status());
  auto report = evaluate(*pairs);
  if (!report.ok()) return Fail("eval", report.status());
  const std::string second_name =
      second ? absl::StrCat("; second judges: ", args->Get("second-judges")) : "";
  std::string text = absl::StrFormat(
      "# Evaluation of %s\n\nJudges: %s%s. Held-out pairs: %d (%s, %s split%s%s).\n\n%s\nStyle / "
      "content "
      "accuracy by dataset (the labels in the clips' names):\n\n%s\nStyle accuracy per "
      "target style%s:\n\n%s",
      args->Get("model"), args->Get("judges"), second_name, pairs->size(),
      model::PairKindName(*kind), model::EvalSplitName(*split),
      library ? absl::StrCat("; style library: ", args->Get("library")) : "",
      args->switches.count("stream") ? "; through a stream, one frame per push" : "",
      report->Markdown(),
      report->ByDatasetMarkdown(*pairs), motion_judge ? " (pose judge / motion-only judge)" : "",
      report->ByStyleMarkdown(*pairs));
  // Charts next to the report: accuracies of every row, and the model's
  // style accuracy per target style.
  const std::string stem = std::filesystem::path(args->Get("out")).replace_extension().string();
  if (const auto parent = std::filesystem::path(args->Get("out")).parent_path(); !parent.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);  // A failure shows when writing.
  }
  std::vector<std::string> row_names;
  BarSeries style{"style", {200, 70, 60}, {}}, content{"content", {60, 110, 190}, {}};
  for (const model::EvalRow& r : report->rows) {
    row_names.push_back(r.name);
    style.values.push_back(r.style_accuracy);
    content.values.push_back(r.content_accuracy);
  }
  std::vector<std::string> targets;
  std::vector<BarSeries> per_style;
  for (int row = 0; row < std::min<int>(2, report->rows.size()); ++row) {
    per_style.push_back(
        {report->rows[row].name, row == 0 ? Rgb{200, 70, 60} : Rgb{240, 160, 60}, {}});
  }
  std::map<std::string, std::array<std::array<int, 2>, 2>> hits;  // style -> row -> (hit, n)
  for (const model::EvalVerdict& v : report->verdicts) {
    if (v.row >= 2) continue;
    const std::optional<motion::ClipLabel> want =
        motion::ParseClipName((*pairs)[v.pair].style_path);
    if (!want) continue;
    auto& h = hits[want->style][v.row];
    h[0] += v.style == want->style;
    h[1] += 1;
  }
  for (const auto& [name, h] : hits) {
    targets.push_back(name);
    for (size_t row = 0; row < per_style.size(); ++row) {
      per_style[row].values.push_back(h[row][1] ? double(h[row][0]) / h[row][1] : 0);
    }
  }
  std::string charts;
  for (const auto& [file, status] :
       {std::pair<std::string, absl::Status>{
            stem + "_accuracy.png", WriteBarChart("Style and content accuracy", row_names,
                                                  {style, content}, stem + "_accuracy.png")},
        {stem + "_styles.png", targets.empty()
                                   ? absl::NotFoundError("no labelled styles")
                                   : WriteBarChart("Style accuracy per target style", targets,
                                                   per_style, stem + "_styles.png")}}) {
    if (status.ok()) {
      const std::string name = std::filesystem::path(file).filename().string();
      absl::StrAppend(&charts, "![", name, "](", name, ")\n");
    } else {
      std::fprintf(stderr, "stylus-tool eval: no chart %s: %s\n", file.c_str(),
                   std::string(status.message()).c_str());
    }
  }
  if (!charts.empty()) text += "\nCharts:\n\n" + charts;
  if (all_kinds) {
    for (const model::StyleLibrary* lib :
         std::vector<const model::StyleLibrary*>{nullptr, library.get()}) {
      for (model::EvalModel& em : models) em.library = lib;
      auto cross =
          model::MakeEvalPairs(args->All("data"), *per, model::PairKind::kCrossAction, *split);
      if (!cross.ok()) return Fail("eval", cross.status());
      auto r = evaluate(*cross);
      if (!r.ok()) return Fail("eval", r.status());
      absl::StrAppendFormat(&text, "\n## Cross-action pairs%s (%d, %s split)\n\n%s\n",
                            lib ? " with the style library" : "", cross->size(),
                            model::EvalSplitName(*split), r->Markdown());
      if (library == nullptr) break;
    }
  }
  if (absl::Status s = motion::WriteFileAtomically(args->Get("out"), text); !s.ok())
    return Fail("eval", s);
  if (args->Has("verdicts")) {
    if (absl::Status s =
            motion::WriteFileAtomically(args->Get("verdicts"), report->VerdictsCsv(*pairs));
        !s.ok())
      return Fail("eval", s);
  }
  std::fputs(text.c_str(), stdout);
  return 0;
}

int StyleMap(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool style-map --model DIR --data DIR... -o codes.svg [--split test|train]\n\n"
      "Encodes the style of every clip of the split (default: held-out) and draws\n"
      "the codes' first two principal components as an SVG scatter coloured by\n"
      "the clips' style labels (the paper's Fig. 2 analogue; labels are only\n"
      "used for the colours).\n";
  int code = 0;
  auto args = ParseOrExit("style-map", argv, {{"model", "data", "out", "split"}, {}}, kHelp, &code);
  if (!args) return code;
  const std::string split = args->Get("split", "test");
  if (!args->Has("model") || !args->Has("data") || !args->Has("out") ||
      (split != "test" && split != "train")) {
    std::fprintf(stderr, "stylus-tool style-map: --model, --data, -o and --split test|train\n\n%s",
                 kHelp);
    return 2;
  }
  auto m = LoadModelSpec(args->Get("model"));
  if (!m.ok()) return Fail("style-map", m.status());
  auto index = motion::IndexDataset(args->All("data"));
  if (!index.ok()) return Fail("style-map", index.status());
  std::vector<model::StylePoint> points;
  for (const motion::ClipEntry* c : index->Split(split == "test")) {
    auto clip = motion::ReadBvhFile(c->path);
    if (!clip.ok()) return Fail("style-map", clip.status());
    auto style = (*m)->EncodeStyle(*clip);
    if (!style.ok()) return Fail("style-map", style.status());
    points.push_back({c->label.style, style->values});
  }
  auto svg = model::StyleMapSvg(
      points, absl::StrFormat("Style codes of %d %s clips, %s (PCA)", points.size(),
                              split == "test" ? "held-out" : "training", args->Get("model")));
  if (!svg.ok()) return Fail("style-map", svg.status());
  if (absl::Status s = motion::WriteFileAtomically(args->Get("out"), *svg); !s.ok())
    return Fail("style-map", s);
  absl::PrintF("wrote %s (%d clips)\n", args->Get("out"), points.size());
  return 0;
}

}  // namespace stylus::tool
