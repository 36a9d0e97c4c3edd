#include "tool/model_spec.h"

#include <filesystem>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "model/family_registry.h"
#include "motion/bvh.h"

namespace stylus::tool {

absl::StatusOr<std::unique_ptr<model::StyleModel>> LoadModelSpec(const std::string& spec) {
  const std::vector<std::string> parts = absl::StrSplit(spec, ':');
  model::ConfigOverrides overrides;
  for (size_t i = 1; i < parts.size(); ++i) {
    const std::vector<std::string> kv = absl::StrSplit(parts[i], absl::MaxSplits('=', 1));
    if (kv.size() != 2 || kv[0].empty()) {
      return absl::InvalidArgumentError("'" + spec + "': ':" + parts[i] +
                                        "' is not KEY=VALUE (e.g. :kc_iters=0)");
    }
    overrides.emplace_back(kv[0] == "kc" ? "kc_iters" : kv[0], kv[1]);
  }
  absl::StatusOr<std::unique_ptr<model::StyleModel>> m =
      model::LoadStyleModel(parts[0], overrides);
  if (m.status().code() == absl::StatusCode::kNotFound &&
      !std::filesystem::exists(parts[0])) {
    // `stylus` names models by id; this tool reads a package folder.
    const std::string as_id = "models/" + parts[0];
    const std::string hint =
        std::filesystem::is_directory(as_id)
            ? absl::StrCat(" (stylus-tool takes a package folder: did you mean --model ", as_id,
                           "?)")
            : " (stylus-tool takes a package folder, models/<name>/<version>, not a "
              "server's model id)";
    return absl::Status(m.status().code(), absl::StrCat(m.status().message(), hint));
  }
  return m;
}

absl::StatusOr<std::vector<NamedModel>> LoadModelAndComparisons(
    const std::string& spec, const std::vector<std::string>& compare) {
  std::vector<NamedModel> out;
  absl::StatusOr<std::unique_ptr<model::StyleModel>> main_model = LoadModelSpec(spec);
  if (!main_model.ok()) return main_model.status();
  out.push_back({spec, *std::move(main_model)});
  for (const std::string& labelled : compare) {
    const size_t eq = labelled.find('=');
    if (eq == std::string::npos || eq == 0) {
      return absl::InvalidArgumentError("--compare wants LABEL=DIR, got '" + labelled + "'");
    }
    absl::StatusOr<std::unique_ptr<model::StyleModel>> m = LoadModelSpec(labelled.substr(eq + 1));
    if (!m.ok()) return m.status();
    out.push_back({labelled.substr(0, eq), *std::move(m)});
  }
  return out;
}

absl::StatusOr<std::vector<motion::Motion>> TransferWithEach(const std::vector<NamedModel>& models,
                                                             const motion::Motion& content,
                                                             const motion::Motion& style,
                                                             motion::PostProcessMode post) {
  std::vector<motion::Motion> out;
  for (const NamedModel& m : models) {
    absl::StatusOr<model::StyleCode> code = m.model->EncodeStyle(style);
    if (!code.ok()) return code.status();
    absl::StatusOr<model::TransferResult> result = m.model->Transfer(content, *code, post);
    if (!result.ok()) return result.status();
    out.push_back(std::move(result->motion));
  }
  return out;
}

absl::StatusOr<ClipPair> ReadClipPair(const std::string& pair) {
  const std::vector<std::string> files = absl::StrSplit(pair, ',');
  if (files.size() != 2) {
    return absl::InvalidArgumentError("--pair wants CONTENT.bvh,STYLE.bvh, got '" + pair + "'");
  }
  absl::StatusOr<motion::Motion> content = motion::ReadBvhFile(files[0]);
  if (!content.ok()) return content.status();
  absl::StatusOr<motion::Motion> style = motion::ReadBvhFile(files[1]);
  if (!style.ok()) return style.status();
  return ClipPair{*std::move(content), *std::move(style), files[0], files[1]};
}

}  // namespace stylus::tool
