// The body-part swap test of a content judge: does it read an action from
// the body part that performs it, or also from how the rest of the body
// moves? Each held-out real clip gets one body part from another real clip,
// and the judge's content verdict on the result is counted
// (docs/notes/contrastive.md):
//  * donor of the same action in another style: the action is still there,
//    only a part's style changed, which is what a style transfer does, so a
//    content judge fit for scoring transfers keeps its verdict;
//  * donor of another action in the same style: a part that does not
//    perform the action changed what it does; a judge that keeps its verdict
//    reads the action from the rest of the body.
#ifndef STYLUS_TOOL_PART_SWAP_TEST_H_
#define STYLUS_TOOL_PART_SWAP_TEST_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "eval/judges.h"

namespace stylus::model {

struct SwapTestCount {
  int clips = 0;  // Held-out clips that had a donor.
  int kept = 0;   // Of those, judged as their own content.
  double accuracy() const { return clips ? static_cast<double>(kept) / clips : 0; }
};

struct SwapTestRow {
  std::string part;            // "legs", "torso", "left-arm", "right-arm".
  SwapTestCount same_action;   // Donor: the same action in another style.
  SwapTestCount other_action;  // Donor: another action in the same style.
};

struct SwapTestReport {
  SwapTestCount unchanged;  // The held-out clips as they are.
  std::vector<SwapTestRow> parts;
  // Per action, all parts pooled: same-action donors.
  std::vector<std::pair<std::string, SwapTestCount>> by_action;
  std::string Markdown() const;
};

// Runs the test on the held-out split of `data` (motion::IndexDataset's).
// Donors come from every clip of the same dataset with at least as many
// frames as the held-out clip, chosen deterministically. `progress` (may be
// empty) gets (done, total) held-out clips.
absl::StatusOr<SwapTestReport> RunSwapTest(const Judges& judges,
                                           const std::vector<std::string>& data,
                                           const std::function<void(int, int)>& progress = {});

}  // namespace stylus::model

#endif  // STYLUS_TOOL_PART_SWAP_TEST_H_
