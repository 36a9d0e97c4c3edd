#include "train/training_run.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "motion/files.h"

namespace stylus::model {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

void LogLine(const std::function<void(const std::string&)>& log, const std::string& line) {
  if (log) {
    log(line);
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
}

std::string TrainingRun::Csv() const {
  std::string csv = absl::StrCat("iteration,", absl::StrJoin(spec_.loss_names, ","), "\n");
  for (const LossRow& r : curve_) {
    absl::StrAppend(&csv, r.iteration);
    for (const std::string& name : spec_.loss_names) {
      absl::StrAppend(&csv, absl::StrFormat(",%.6g", r.Get(name)));
    }
    csv += "\n";
  }
  return csv;
}

absl::Status TrainingRun::SaveCheckpoint() {
  const std::string dir = spec_.out + "/checkpoint", tmp = spec_.out + "/checkpoint.tmp";
  std::error_code ec;
  fs::remove_all(tmp, ec);
  fs::create_directories(tmp, ec);
  if (ec) return absl::InternalError(absl::StrCat(tmp, ": ", ec.message()));
  if (absl::Status s = spec_.save_tensors(tmp); !s.ok()) return s;
  std::ostringstream rng_text;
  rng_text << rng_;
  const std::string csv = Csv();
  for (const auto& [name, text] :
       {std::pair<std::string, std::string>{"state.txt",
                                            absl::StrCat(iteration_, "\n", rng_text.str(), "\n")},
        {"config.txt", spec_.config_text},
        {"loss.csv", csv}}) {
    if (absl::Status s = motion::WriteFileAtomically(tmp + "/" + name, text); !s.ok()) return s;
  }
  // Swap in the new checkpoint: the old one stays until the new is complete.
  fs::remove_all(dir + ".old", ec);
  if (fs::exists(dir)) fs::rename(dir, dir + ".old", ec);
  fs::rename(tmp, dir, ec);
  if (ec) return absl::InternalError(absl::StrCat(dir, ": ", ec.message()));
  fs::remove_all(dir + ".old", ec);
  return spec_.write_package(iteration_, csv);
}

absl::Status TrainingRun::Resume(const std::function<std::string(const std::string&)>& comparable) {
  const std::string dir = spec_.out + "/checkpoint";
  if (!fs::exists(dir + "/state.txt")) {
    Log("no checkpoint in " + dir + "; starting from scratch");
    return absl::OkStatus();
  }
  std::ifstream config(dir + "/config.txt");
  std::stringstream saved;
  saved << config.rdbuf();
  if (comparable(saved.str()) != comparable(spec_.config_text)) {
    return absl::FailedPreconditionError(
        absl::StrCat(dir,
                     " was made with another configuration or data; train into a new --out or drop "
                     "--resume"));
  }
  std::ifstream state(dir + "/state.txt");
  std::string line, rng_line;
  if (!std::getline(state, line) || !absl::SimpleAtoi(line, &iteration_) ||
      !std::getline(state, rng_line)) {
    return absl::DataLossError(dir + "/state.txt: unreadable");
  }
  std::istringstream rng_text(rng_line);
  rng_text >> rng_;
  curve_.clear();
  std::ifstream csv(dir + "/loss.csv");
  std::getline(csv, line);  // Header.
  while (std::getline(csv, line)) {
    const std::vector<std::string> v = absl::StrSplit(line, ',');
    if (v.size() != spec_.loss_names.size() + 1) continue;
    LossRow r;
    bool ok = absl::SimpleAtoi(v[0], &r.iteration);
    for (size_t i = 1; i < v.size(); ++i) {
      double x = 0;
      ok = ok && absl::SimpleAtod(v[i], &x);
      r.values[spec_.loss_names[i - 1]] = x;
    }
    if (ok) curve_.push_back(r);
  }
  if (absl::Status s = spec_.load_tensors(dir); !s.ok()) {
    return absl::DataLossError(absl::StrCat(dir, ": unreadable checkpoint: ", s.message()));
  }
  Log(absl::StrCat("resumed from ", dir, " at iteration ", iteration_));
  return absl::OkStatus();
}

absl::Status TrainingRun::Run(const std::function<Losses(int iteration)>& step) {
  const size_t n = spec_.loss_names.size();
  std::vector<double> sum(n, 0);
  int in_sum = 0;
  const auto t0 = Clock::now();
  const int start = iteration_;
  while (iteration_ < spec_.iterations) {
    const Losses losses = step(iteration_);
    ++iteration_;
    if (losses.size() != n) {
      return absl::InternalError(
          absl::StrCat("the trainer reported ", losses.size(), " losses; it declared ", n));
    }
    for (size_t i = 0; i < n; ++i) {
      const auto it = losses.find(spec_.loss_names[i]);
      if (it == losses.end()) {
        return absl::InternalError(
            absl::StrCat("the trainer did not report loss '", spec_.loss_names[i], "'"));
      }
      if (!std::isfinite(it->second)) {
        return absl::InternalError(absl::StrCat("loss '", spec_.loss_names[i],
                                                "' became non-finite at iteration ", iteration_));
      }
      sum[i] += it->second;
    }
    ++in_sum;
    if (iteration_ % spec_.log_every == 0 || iteration_ == spec_.iterations) {
      LossRow row{iteration_, {}};
      std::string line = absl::StrFormat("iter %d/%d ", iteration_, spec_.iterations);
      for (size_t i = 0; i < n; ++i) {
        const double mean = sum[i] / in_sum;
        row.values[spec_.loss_names[i]] = mean;
        absl::StrAppend(&line, absl::StrFormat(" %s %.4f", spec_.loss_names[i], mean));
      }
      curve_.push_back(row);
      if (spec_.on_record) spec_.on_record(row);
      const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
      const double its = (iteration_ - start) / std::max(secs, 1e-9);
      absl::StrAppend(&line,
                      absl::StrFormat("  |  %.1f it/s  ETA %.0f s", its,
                                      (spec_.iterations - iteration_) / std::max(its, 1e-9)));
      Log(line);
      std::fill(sum.begin(), sum.end(), 0);
      in_sum = 0;
    }
    if (iteration_ % spec_.checkpoint_every == 0 && iteration_ < spec_.iterations) {
      if (absl::Status s = SaveCheckpoint(); !s.ok()) return s;
    }
  }
  return SaveCheckpoint();
}

}  // namespace stylus::model
