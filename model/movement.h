// Where a transfer's movement comes from (MovementKeys, model/config_text.h;
// docs/movement.md): the style clip itself when it shows the content's kind
// of movement, else the best-matching take of a style library, else the
// network's output as it is.
//
// A style library is a folder of BVH takes on any humanoid rig with their
// style labels (from Bandai-style names or a labels CSV). Per model, its
// takes are brought onto the model's skeleton and rate, read for
// registration (motion/example_motion.h) and encoded once, on first use.
// A style the model was never trained on is taught by pointing at its takes.
#ifndef STYLUS_MODEL_MOVEMENT_H_
#define STYLUS_MODEL_MOVEMENT_H_

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/example_motion.h"
#include "motion/live_movement.h"
#include "motion/motion.h"

namespace stylus::model {

class StyleModel;
struct StyleCode;
struct MovementKeys;

// What movement a transfer got (TransferResult::movement).
struct MovementNote {
  bool applied = false;
  std::string example;  // "style clip", or the library take's file name.
  std::string kind;     // "steps" or "gesture".
  double cost = 0;      // How well the example fits: gestures' registration cost, steps' mismatch.
  double rate = 1;      // Example frames played per content frame (mean).
  std::string reason;   // Why not applied.
};

struct LibraryTake {
  std::string path;
  std::string style;
  std::string content;  // The action, when its label names one ("" otherwise).
};

class StyleLibrary {
 public:
  // Every .bvh under `dir` (recursively) with a style label: from its name
  // (dataset-N_{content}_{style}_{take}.bvh) or from `labels_csv`
  // (clip,content,style rows, paths relative to the CSV's folder). Files
  // without a label are skipped and listed. `exclude`: file names (no
  // folder) left out, e.g. the takes an evaluation's judges were trained on.
  // NOT_FOUND when the folder is missing or holds no labelled take;
  // INVALID_ARGUMENT for a malformed CSV or a take that cannot be read
  // (naming the file).
  static absl::StatusOr<std::unique_ptr<StyleLibrary>> Load(
      const std::string& dir, const std::string& labels_csv = "",
      const std::vector<std::string>& exclude = {});

  const std::vector<LibraryTake>& takes() const { return takes_; }
  std::vector<std::string> Styles() const;  // Sorted, unique.
  const std::vector<std::string>& skipped() const { return skipped_; }
  const std::string& dir() const { return dir_; }

  // The takes of `style` on `model`'s skeleton and rate, read for
  // registration; the first call for a model converts and reads all takes.
  struct Converted {
    std::vector<std::shared_ptr<const motion::MovementClip>> clips;  // Per take.
    std::map<std::string, std::vector<float>> mean_code;             // Per style.
    // Per take, its action as a reading of the model's content guard: its
    // label's when the guard knows it, else the guard's reading; empty
    // without a guard.
    std::vector<std::vector<double>> action;
  };
  absl::StatusOr<std::shared_ptr<const Converted>> For(const StyleModel& model) const;

 private:
  std::string dir_;
  std::vector<LibraryTake> takes_;
  std::vector<motion::Motion> clips_;
  std::vector<std::string> skipped_;
  mutable std::mutex mu_;
  mutable std::map<std::string, std::shared_ptr<const Converted>> converted_;
};

// The style of the library nearest `code` (cosine of the mean codes of its
// takes); empty when the library has none.
std::string NearestLibraryStyle(const StyleLibrary::Converted& converted, const StyleCode& code);

struct MovementRequest {
  const StyleLibrary* library = nullptr;
  // The target style's label in the library; empty: the style whose takes'
  // codes are nearest the style's.
  std::string style_label;
};

// The example a transfer of `content` (at the model's rate, on its
// skeleton) takes its movement from: of the dominant style of `styles` (the
// largest share), the style clip or a library take, whichever shows the
// content's movement best. nullopt (with the note's reason) when none does.
struct ChosenExample {
  std::shared_ptr<const motion::MovementClip> content, example;
  motion::Registration registration;
};
absl::StatusOr<std::optional<ChosenExample>> ChooseExample(
    const StyleModel& model, const motion::Motion& content, const std::vector<StyleCode>& styles,
    const std::vector<double>& shares, const MovementKeys& keys, const MovementRequest& request,
    MovementNote* note);

// The takes a stream of `code`'s style plays (motion/live_movement.h): the
// style clip when the code holds its reading (EncodeStyle), then the
// library's takes of the style (`request.style_label`, else the nearest
// style): those that step as steps, the others as gestures, at most
// StreamExamples::kMaxTakes of each. Empty when there are
// none; `why` then says why.
absl::StatusOr<motion::StreamExamples> ChooseStreamExamples(const StyleModel& model,
                                                            const StyleCode& code,
                                                            const MovementRequest& request,
                                                            std::string* why = nullptr);

// How many times as long the content takes at the example's pace: steps,
// the content's path at the example's speed (content speed / example speed);
// a gesture, the example's duration over the content's.
double StylePace(const ChosenExample& chosen);

// The network's transfer `network` of the chosen example's content, with
// the example's movement in the parts `keys` say (motion::ApplyMovement).
absl::StatusOr<motion::MovementResult> ApplyExample(const motion::Motion& network,
                                                    const ChosenExample& chosen,
                                                    const MovementKeys& keys);

}  // namespace stylus::model

#endif  // STYLUS_MODEL_MOVEMENT_H_
