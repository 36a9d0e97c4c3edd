#include "model/contrastive_trainer.h"

#include <torch/torch.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "model/contrastive_net.h"
#include "model/package.h"
#include "model/runtime.h"
#include "model/training_set.h"
#include "motion/files.h"

namespace stylus::model {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string CsvHeader() { return "iteration,rec,gan,nce,tri,disc,total\n"; }
std::string CsvRow(const LossRecord& r) {
  return absl::StrFormat("%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", r.iteration, r.rec, r.gan, r.nce,
                         r.tri, r.disc, r.total);
}

// Everything a resumed run needs, besides the tensors.
struct TrainState {
  int iteration = 0;
  std::string rng;  // std::mt19937_64 state.
  std::vector<LossRecord> curve;
};

absl::StatusOr<TrainState> ReadState(const std::string& dir) {
  std::ifstream f(dir + "/state.txt");
  if (!f) return absl::NotFoundError(dir + "/state.txt: missing");
  TrainState s;
  std::string line;
  std::getline(f, line);
  s.iteration = std::stoi(line);
  std::getline(f, s.rng);
  std::ifstream csv(dir + "/loss.csv");
  std::getline(csv, line);  // Header.
  while (std::getline(csv, line)) {
    std::vector<std::string> v = absl::StrSplit(line, ',');
    if (v.size() != 7) continue;
    LossRecord r;
    r.iteration = std::stoi(v[0]);
    r.rec = std::stod(v[1]), r.gan = std::stod(v[2]), r.nce = std::stod(v[3]);
    r.tri = std::stod(v[4]), r.disc = std::stod(v[5]), r.total = std::stod(v[6]);
    s.curve.push_back(r);
  }
  return s;
}

struct Trainer {
  const TrainOptions& opt;
  ContrastiveConfig config;
  TrainingSet data;
  ContrastiveNet net{nullptr};
  Discriminator disc{nullptr};
  std::unique_ptr<torch::optim::Adam> opt_g, opt_d;
  torch::Tensor content_mask;  // (1, dim, 1): channels of the content-keeping term.
  std::mt19937_64 rng;
  TrainState state;

  void Log(const std::string& s) const {
    if (opt.log) {
      opt.log(s);
    } else {
      std::fprintf(stderr, "%s\n", s.c_str());
    }
  }

  torch::Tensor ToTensor(std::vector<float>* buf) const {
    return torch::from_blob(buf->data(), {config.batch, config.dim, config.window},
                            torch::kFloat32)
        .clone();
  }

  // A batch of windows and, with cross_view, a second window of the same clip
  // for each (its style view); without, the same windows.
  std::pair<torch::Tensor, torch::Tensor> Batch() {
    std::vector<float> buf;
    std::vector<int> clips;
    data.SampleBatch(config.batch, config.window, &rng, &buf, &clips);
    torch::Tensor x = ToTensor(&buf);
    if (!config.cross_view) return {x, x};
    data.SampleFromClips(clips, config.window, &rng, &buf);
    return {x, ToTensor(&buf)};
  }

  LossRecord Step() {
    const auto [x_t, v_t] = Batch();
    const auto [x_s, v_s] = Batch();
    const torch::Tensor c_t = net->content(x_t), s_t = net->style(v_t);
    const torch::Tensor c_s = net->content(x_s), s_s = net->style(v_s);
    const torch::Tensor rec = (ReconstructionLoss(net->decode(c_t, s_t), x_t) +
                               ReconstructionLoss(net->decode(c_s, s_s), x_s)) /
                              2;
    const torch::Tensor x_g = net->decode(c_t, s_s);
    LossRecord r;
    torch::Tensor total = rec;
    if (config.alpha > 0) {
      opt_d->zero_grad();
      const torch::Tensor d_loss =
          DiscriminatorGanLoss(disc->forward(x_s), disc->forward(x_g.detach()));
      d_loss.backward();
      opt_d->step();
      r.disc = d_loss.item<double>();
      const torch::Tensor gan = GeneratorGanLoss(disc->forward(x_g));
      r.gan = gan.item<double>();
      total = total + config.alpha * gan;
    }
    if (config.content_weight > 0) {
      const torch::Tensor keep = ((x_g - x_t).abs() * content_mask).sum() /
                                 (content_mask.sum() * x_g.size(0) * x_g.size(2));
      total = total + config.content_weight * keep;
    }
    if (config.use_nce && config.beta > 0) {
      const torch::Tensor nce = NceLoss(net->content(x_g), c_t, net->nce_w, config.temperature);
      r.nce = nce.item<double>();
      total = total + config.beta * nce;
    }
    if (config.use_tri && config.gamma > 0) {
      // Positive: the style clip's code from its own window (the other view
      // already fed G), so the pair is two views of one clip.
      const torch::Tensor tri = TripletLoss(
          net->style(x_g), config.cross_view ? net->style(x_s) : s_s, s_t, config.margin);
      r.tri = tri.item<double>();
      total = total + config.gamma * tri;
    }
    opt_g->zero_grad();
    total.backward();
    opt_g->step();
    r.rec = rec.item<double>();
    r.total = total.item<double>();
    return r;
  }

  absl::Status SaveCheckpoint() {
    const std::string dir = opt.out + "/checkpoint", tmp = opt.out + "/checkpoint.tmp";
    std::error_code ec;
    fs::remove_all(tmp, ec);
    fs::create_directories(tmp, ec);
    if (ec) return absl::InternalError(absl::StrCat(tmp, ": ", ec.message()));
    try {
      torch::save(net, tmp + "/net.pt");
      torch::save(disc, tmp + "/disc.pt");
      torch::save(*opt_g, tmp + "/opt_g.pt");
      torch::save(*opt_d, tmp + "/opt_d.pt");
    } catch (const std::exception& e) {
      return absl::InternalError(absl::StrCat("saving checkpoint: ", e.what()));
    }
    std::ostringstream rng_text;
    rng_text << rng;
    std::string csv = CsvHeader();
    for (const LossRecord& r : state.curve) csv += CsvRow(r);
    if (absl::Status s = motion::WriteFileAtomically(
            tmp + "/state.txt", absl::StrCat(state.iteration, "\n", rng_text.str(), "\n"));
        !s.ok())
      return s;
    if (absl::Status s = motion::WriteFileAtomically(tmp + "/config.txt", config.Serialize());
        !s.ok())
      return s;
    if (absl::Status s = motion::WriteFileAtomically(tmp + "/loss.csv", csv); !s.ok()) return s;
    // Swap in the new checkpoint: the old one stays until the new is complete.
    fs::remove_all(dir + ".old", ec);
    if (fs::exists(dir)) fs::rename(dir, dir + ".old", ec);
    fs::rename(tmp, dir, ec);
    if (ec) return absl::InternalError(absl::StrCat(dir, ": ", ec.message()));
    fs::remove_all(dir + ".old", ec);
    return WritePackage(csv);
  }

  absl::Status WritePackage(const std::string& csv) {
    ContrastiveConfig c = config;
    c.trained_iterations = state.iteration;
    if (absl::Status s = WritePackageFiles(opt.out, c, data.norm, data.skeleton, data.frame_time);
        !s.ok())
      return s;
    try {
      torch::save(net, opt.out + "/weights.pt.tmp");
    } catch (const std::exception& e) {
      return absl::InternalError(absl::StrCat("saving weights: ", e.what()));
    }
    std::error_code ec;
    fs::rename(opt.out + "/weights.pt.tmp", opt.out + "/weights.pt", ec);
    if (ec) return absl::InternalError(absl::StrCat(opt.out, "/weights.pt: ", ec.message()));
    return motion::WriteFileAtomically(opt.out + "/loss.csv", csv);
  }

  torch::Tensor ContentMask() const {
    const motion::Skeleton& sk = data.skeleton;
    const motion::FeatureLayout layout(sk.num_joints());
    torch::Tensor mask = torch::zeros({1, config.dim, 1});
    std::vector<bool> leg(sk.num_joints(), false);
    for (int j = 0; j < sk.num_joints(); ++j) {
      const int p = sk.joint(j).parent;
      leg[j] = j == data.roles.left_hip || j == data.roles.right_hip || (p >= 0 && leg[p]);
      if (!leg[j]) continue;
      for (int c = 0; c < 3; ++c) mask[0][layout.position(j) + c][0] = 1;
      for (int c = 0; c < 4; ++c) mask[0][layout.rotation(j) + c][0] = 1;
    }
    for (int c = 0; c < 8; ++c) mask[0][layout.trajectory() + c][0] = 1;
    return mask;
  }

  absl::Status Resume() {
    const std::string dir = opt.out + "/checkpoint";
    if (!fs::exists(dir + "/state.txt")) {
      Log("no checkpoint in " + dir + "; starting from scratch");
      return absl::OkStatus();
    }
    std::ifstream f(dir + "/config.txt");
    std::stringstream ss;
    ss << f.rdbuf();
    absl::StatusOr<ContrastiveConfig> saved =
        ContrastiveConfig::Parse(ss.str(), dir + "/config.txt");
    if (!saved.ok()) return saved.status();
    ContrastiveConfig a = *saved, b = config;
    a.iterations = b.iterations = 0;  // A resumed run may go longer.
    a.trained_iterations = b.trained_iterations = 0;
    if (a.Serialize() != b.Serialize()) {
      return absl::FailedPreconditionError(absl::StrCat(
          dir,
          " was made with another configuration or data; train into a new --out or drop --resume"));
    }
    absl::StatusOr<TrainState> s = ReadState(dir);
    if (!s.ok()) return s.status();
    state = *std::move(s);
    std::istringstream rng_text(state.rng);
    rng_text >> rng;
    try {
      torch::load(net, dir + "/net.pt");
      torch::load(disc, dir + "/disc.pt");
      torch::load(*opt_g, dir + "/opt_g.pt");
      torch::load(*opt_d, dir + "/opt_d.pt");
    } catch (const std::exception& e) {
      return absl::DataLossError(absl::StrCat(dir, ": unreadable checkpoint: ", e.what()));
    }
    Log(absl::StrCat("resumed from ", dir, " at iteration ", state.iteration));
    return absl::OkStatus();
  }

  absl::Status Run() {
    SetComputeThreads(opt.threads);
    const auto t_load = Clock::now();
    absl::StatusOr<TrainingSet> loaded = LoadTrainingSet(opt.data, {config.window, config.hop});
    if (!loaded.ok()) return loaded.status();
    data = *std::move(loaded);
    config.dim = data.dim();
    config.data = absl::StrJoin(opt.data, ";");
    config.commit = opt.commit;
    Log(absl::StrFormat("loaded %d clips, %d windows of %d frames, %d channels in %.1f s",
                        data.clips.size(), data.windows.size(), config.window, config.dim,
                        std::chrono::duration<double>(Clock::now() - t_load).count()));
    content_mask = ContentMask();
    torch::manual_seed(config.seed);
    rng.seed(config.seed);
    net = ContrastiveNet(config);
    disc = Discriminator(config);
    opt_g = std::make_unique<torch::optim::Adam>(
        net->parameters(), torch::optim::AdamOptions(config.lr).betas({0.5, 0.999}));
    opt_d = std::make_unique<torch::optim::Adam>(
        disc->parameters(), torch::optim::AdamOptions(config.lr).betas({0.5, 0.999}));
    if (opt.resume) {
      if (absl::Status s = Resume(); !s.ok()) return s;
    }
    LossRecord sum;
    int in_sum = 0;
    auto t0 = Clock::now();
    const int start = state.iteration;
    while (state.iteration < config.iterations) {
      const LossRecord r = Step();
      ++state.iteration;
      sum.rec += r.rec, sum.gan += r.gan, sum.nce += r.nce, sum.tri += r.tri, sum.disc += r.disc,
          sum.total += r.total;
      ++in_sum;
      if (!std::isfinite(r.total)) {
        return absl::InternalError(
            absl::StrCat("loss became non-finite at iteration ", state.iteration));
      }
      if (state.iteration % opt.log_every == 0 || state.iteration == config.iterations) {
        LossRecord avg{state.iteration,  sum.rec / in_sum,  sum.gan / in_sum,  sum.nce / in_sum,
                       sum.tri / in_sum, sum.disc / in_sum, sum.total / in_sum};
        state.curve.push_back(avg);
        if (opt.on_record) opt.on_record(avg);
        const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
        const double its = (state.iteration - start) / std::max(secs, 1e-9);
        Log(absl::StrFormat(
            "iter %d/%d  rec %.4f  gan %.4f  nce %.4f  tri %.4f  disc %.4f  |  %.1f it/s  ETA %.0f "
            "s",
            state.iteration, config.iterations, avg.rec, avg.gan, avg.nce, avg.tri, avg.disc, its,
            (config.iterations - state.iteration) / std::max(its, 1e-9)));
        sum = LossRecord();
        in_sum = 0;
      }
      if (state.iteration % opt.checkpoint_every == 0 && state.iteration < config.iterations) {
        if (absl::Status s = SaveCheckpoint(); !s.ok()) return s;
      }
    }
    return SaveCheckpoint();
  }
};

}  // namespace

absl::Status TrainContrastive(const TrainOptions& options) {
  if (options.out.empty()) return absl::InvalidArgumentError("no output directory (--out)");
  if (options.data.empty()) return absl::InvalidArgumentError("no training data (--data)");
  if (options.config.batch <= 0 || options.log_every <= 0 || options.checkpoint_every <= 0) {
    return absl::InvalidArgumentError("batch, log and checkpoint intervals must be positive");
  }
  Trainer t{options, options.config, {}, nullptr, nullptr, nullptr, nullptr, {}, {}, {}};
  try {
    return t.Run();
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("training failed: ", e.what()));
  }
}

}  // namespace stylus::model
