// stylus: the command-line client of a Stylus server.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <fstream>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "cli/args.h"
#include "client/client.h"
#include "client/schedule_file.h"
#include "formats/scene_file.h"
#include "motion/bvh.h"

namespace {

using stylus::cli::Args;

constexpr char kUsage[] =
    "usage: stylus COMMAND [options]   (stylus COMMAND --help for a command's options)\n\n"
    "Calls a Stylus server.\n\n"
    "commands:\n"
    "%s\n"
    "global options (before or after the command):\n"
    "  --server ADDR      the server (default $STYLUS_SERVER, else localhost:50051)\n"
    "  --deadline-s S     give up on a call after S seconds (default 60)\n"
    "  --token TOKEN      the server's access token (default $STYLUS_TOKEN)\n"
    "  --tls-ca FILE      speak TLS, trusting the CAs in this PEM file (default\n"
    "                     $STYLUS_TLS_CA; 'system': the system's CAs)\n"
    "  --tls-cert FILE    mutual TLS: this client's PEM certificate...\n"
    "  --tls-key FILE     ...and its key\n";

constexpr char kCallOptions[] =
    "  --model NAME[/VERSION]   the model (default: the server's default)\n"
    "  --postprocess default|none|feet|full   clean-up of the output (default: the\n"
    "                           server's, full)\n"
    "  --joint-map FILE         for clips on another rig than the model's: humanoid\n"
    "                           roles not to guess, lines like 'left_foot = MyFootL'\n"
    "                           (also used for style clips on the content's rig)\n"
    "  --animation NAME         in files with several animations (FBX, glTF), the\n"
    "                           one to read\n\n"
    "Clips are BVH, FBX, glTF (.gltf, .glb) or COLLADA (.dae) files; outputs are\n"
    "written as .bvh, .gltf or .glb by their extension. A glTF output of an FBX or\n"
    "glTF content keeps the content's nodes, meshes and skins: only the animation\n"
    "changes.\n";

// The server's address, for the hint when it cannot be reached.
std::string server_address;  // NOLINT: set once in main.

int Fail(const std::string& command, const absl::Status& status) {
  std::fprintf(stderr, "stylus %s: %s: %s\n", command.c_str(),
               absl::StatusCodeToString(status.code()).c_str(),
               std::string(status.message()).c_str());
  if (status.code() == absl::StatusCode::kUnavailable) {
    std::fprintf(stderr,
                 "stylus %s: the call did not get through to a serving Stylus server at %s: "
                 "check that one runs there (stylus-server), or name another with --server "
                 "HOST:PORT or STYLUS_SERVER (a TLS server also needs --tls-ca)\n",
                 command.c_str(), server_address.c_str());
  }
  return 1;
}

// OK when a file can be written at `path` (its folder exists and is
// writable): checked before a call, so that no work is lost at the end.
absl::Status CheckWritable(const std::string& path, const std::string& flag) {
  absl::StatusOr<stylus::formats::FileFormat> format = stylus::formats::FormatOfPath(path);
  if (!format.ok()) return format.status();
  if (!stylus::formats::CanWrite(*format)) {
    return absl::InvalidArgumentError(absl::StrCat(flag, " ", path, ": stylus writes ",
                                                   stylus::formats::WritableFormats()));
  }
  std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    return absl::InvalidArgumentError(absl::StrCat(
        flag, " ", path, ": the folder ", folder.string(), " does not exist; create it first"));
  }
  if (access(folder.c_str(), W_OK) != 0) {
    return absl::PermissionDeniedError(
        absl::StrCat(flag, " ", path, ": the folder ", folder.string(), " is not writable"));
  }
  return absl::OkStatus();
}

// Reads a clip in any format the formats library reads; --animation picks
// one of several in a scene file.
absl::StatusOr<stylus::motion::Motion> Read(const std::string& path, const std::string& what,
                                            const Args& a) {
  if (path.empty()) return absl::InvalidArgumentError(absl::StrCat("--", what, " is required"));
  stylus::formats::ReadOptions options;
  options.animation = a.Get("animation");
  return stylus::formats::ReadMotionFile(path, options);
}

// True when `path` names a clip file by its extension (else it is a name).
bool IsClipPath(const std::string& path) { return stylus::formats::FormatOfPath(path).ok(); }

// Writes an output clip by its extension; a glTF output keeps the content
// file's scene when the content was one.
absl::Status Write(const stylus::motion::Motion& m, const std::string& path, const Args& a) {
  stylus::formats::WriteOptions options;
  options.like = a.Get("content");
  return stylus::formats::WriteMotionFile(m, path, options);
}

absl::StatusOr<stylus::CallOptions> Common(const Args& a) {
  stylus::CallOptions o;
  o.model = a.Get("model");
  absl::StatusOr<stylus::v1::PostProcess> post =
      stylus::ParsePostProcess(a.Get("postprocess", "default"));
  if (!post.ok()) return post.status();
  o.postprocess = *post;
  if (a.Has("joint-map")) {
    absl::StatusOr<stylus::motion::JointMap> map =
        stylus::motion::ReadJointMapFile(a.Get("joint-map"));
    if (!map.ok()) return map.status();
    o.joint_map = *std::move(map);
  }
  return o;
}

// The call's style: --style-name NAME (saved on the server), else the
// --style clip, read into `clip` (which the result points into).
absl::StatusOr<stylus::Style> StyleArg(const Args& a, const stylus::CallOptions& opts,
                                       const stylus::motion::Motion& content,
                                       std::optional<stylus::motion::Motion>* clip) {
  stylus::Style ref;
  if (a.Has("style-name")) {
    ref.name = a.Get("style-name");
    return ref;
  }
  absl::StatusOr<stylus::motion::Motion> read = Read(a.Get("style"), "style", a);
  if (!read.ok()) return read.status();
  *clip = *std::move(read);
  ref.clip = &**clip;
  if ((*clip)->skeleton.SameTopology(content.skeleton)) ref.joint_map = opts.joint_map;
  return ref;
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5));
  return v[i];
}

int Models(stylus::Client& client) {
  auto models = client.ListModels();
  if (!models.ok()) return Fail("models", models.status());
  for (const auto& m : *models) {
    absl::PrintF("%s%s  family=%s joints=%d fps=%.1f window=%d hop=%d iterations=%d%s\n", m.id(),
                 m.is_default() ? " (default)" : "", m.family(), m.skeleton().joints_size(),
                 m.fps(), m.window(), m.hop(), m.trained_iterations(),
                 m.live() ? absl::StrCat(" live lookahead=", m.lookahead()) : "");
  }
  return 0;
}

int Health(stylus::Client& client) {
  absl::StatusOr<bool> serving = client.Serving();
  if (!serving.ok()) return Fail("health", serving.status());
  absl::PrintF("%s\n", *serving ? "SERVING" : "NOT_SERVING");
  return *serving ? 0 : 1;
}

int ModelInfo(stylus::Client& client, const Args& a) {
  auto m = client.GetModel(a.Get("model"));
  if (!m.ok()) return Fail("model-info", m.status());
  absl::PrintF(
      "id %s\nfamily %s\nversion %s\ndefault %s\njoints %d\nfps %.3f\nwindow %d\nhop %d\n"
      "trained_iterations %d\nstreams %s\nsaved_styles %s\n",
      m->id(), m->family(), m->version(), m->is_default() ? "yes" : "no",
      m->skeleton().joints_size(), m->fps(), m->window(), m->hop(), m->trained_iterations(),
      m->live() ? absl::StrCat("live, lookahead ", m->lookahead(), " frames")
                : "in windows (offline)",
      m->saved_styles().empty() ? "(none)" : absl::StrJoin(m->saved_styles(), ", "));
  return 0;
}

int Load(stylus::Client& client, const Args& a) {
  if (a.Get("model").empty())
    return Fail("load", absl::InvalidArgumentError("--model is required"));
  auto m = client.LoadModel(a.Get("model"));
  if (!m.ok()) return Fail("load", m.status());
  absl::PrintF("loaded %s%s\n", m->id(), m->is_default() ? " (default)" : "");
  return 0;
}

int Unload(stylus::Client& client, const Args& a) {
  if (a.Get("model").empty()) {
    return Fail("unload", absl::InvalidArgumentError("--model is required"));
  }
  if (absl::Status s = client.UnloadModel(a.Get("model")); !s.ok()) return Fail("unload", s);
  absl::PrintF("unloaded %s\n", a.Get("model"));
  return 0;
}

int Transfer(stylus::Client& client, const Args& a) {
  auto opts = Common(a);
  if (!opts.ok()) return Fail("transfer", opts.status());
  auto content = Read(a.Get("content"), "content", a);
  if (!content.ok()) return Fail("transfer", content.status());
  std::optional<stylus::motion::Motion> style_clip;
  absl::StatusOr<stylus::Style> ref = StyleArg(a, *opts, *content, &style_clip);
  if (!ref.ok()) return Fail("transfer", ref.status());
  if (a.Get("out").empty()) return Fail("transfer", absl::InvalidArgumentError("-o is required"));
  if (absl::Status w = CheckWritable(a.Get("out"), "-o"); !w.ok()) return Fail("transfer", w);
  const std::string timing = a.Get("timing", "content");
  if (timing != "content" && timing != "style") {
    return Fail("transfer", absl::InvalidArgumentError(absl::StrCat(
                                "--timing must be content or style, not '", timing, "'")));
  }
  opts->timing = timing == "style" ? stylus::v1::TIMING_STYLE : stylus::v1::TIMING_CONTENT;
  if (a.Has("fit-frames")) {
    if (!absl::SimpleAtoi(a.Get("fit-frames"), &opts->fit_frames) || opts->fit_frames < 2) {
      return Fail("transfer", absl::InvalidArgumentError(absl::StrCat(
                                  "--fit-frames wants a frame count of 2 or more, not '",
                                  a.Get("fit-frames"), "'")));
    }
  }
  stylus::v1::MovementNote movement;
  opts->movement = &movement;
  stylus::v1::ContentGuardNote guard;
  opts->content_guard = &guard;
  stylus::v1::TimeWarp warp;
  opts->time_warp = &warp;
  auto out = client.Transfer(*content, *ref, *opts);
  if (!out.ok()) return Fail("transfer", out.status());
  if (absl::Status s = Write(*out, a.Get("out"), a); !s.ok()) {
    return Fail("transfer", s);
  }
  std::string warp_note;
  if (opts->timing == stylus::v1::TIMING_STYLE || opts->fit_frames > 0) {
    warp_note =
        !warp.applied() ? absl::StrCat(" (style timing not applied: ", warp.reason(), ")")
        : warp.style_period_s() > 0
            ? absl::StrFormat(" (style timing: cadence %.2f s -> %.2f s, played %.2fx as long)",
                              warp.content_period_s(), warp.style_period_s(), warp.ratio())
            : absl::StrFormat(" (played %.2fx as long)", warp.ratio());
  }
  if (!movement.kind().empty() || !movement.reason().empty()) {
    warp_note +=
        movement.applied()
            ? absl::StrFormat(" (movement: %s from %s)", movement.kind(), movement.example())
            : absl::StrCat(" (movement: the network's; ", movement.reason(), ")");
  }
  absl::PrintF(
      "wrote %s (%d frames)%s%s\n", a.Get("out"), out->num_frames,
      guard.backed_off()
          ? absl::StrFormat(" (content guard: the transfer as configured read as another action "
                            "than the content's; returned instead: the content plus %g x the "
                            "change the style makes%s; docs/families.md \"The content guard\")",
                            guard.residual_strength(),
                            guard.residual_strength() == 0 ? ", i.e. no style" : "")
          : "",
      warp_note);
  return 0;
}

int Interpolate(stylus::Client& client, const Args& a) {
  auto opts = Common(a);
  if (!opts.ok()) return Fail("interpolate", opts.status());
  auto content = Read(a.Get("content"), "content", a);
  if (!content.ok()) return Fail("interpolate", content.status());
  // Each --style: a clip (.bvh) or a saved style's name, in the order given.
  const std::vector<std::string> given = a.All("style");
  std::vector<std::unique_ptr<stylus::motion::Motion>> clips;
  std::vector<stylus::Style> styles;
  for (const std::string& p : given) {
    if (!IsClipPath(p)) {
      styles.push_back({nullptr, p});
      continue;
    }
    auto s = Read(p, "style", a);
    if (!s.ok()) return Fail("interpolate", s.status());
    clips.push_back(std::make_unique<stylus::motion::Motion>(*std::move(s)));
    const stylus::motion::Motion& c = *clips.back();
    styles.push_back({&c, "",
                      c.skeleton.SameTopology(content->skeleton) ? opts->joint_map
                                                                 : stylus::motion::JointMap{}});
  }
  if (styles.size() < 2) {
    return Fail("interpolate",
                absl::InvalidArgumentError("give two or more --style clips (.bvh) or saved names"));
  }
  // -o PREFIX[.bvh|.gltf|.glb]: PREFIX_0.EXT, PREFIX_1.EXT, ... (BVH by default).
  std::string prefix = a.Get("out");
  if (prefix.empty())
    return Fail("interpolate", absl::InvalidArgumentError("-o PREFIX is required"));
  std::string extension = ".bvh";
  if (IsClipPath(prefix)) {
    extension = prefix.substr(prefix.find_last_of('.'));
    prefix.resize(prefix.size() - extension.size());
  }
  if (absl::Status w = CheckWritable(prefix + extension, "-o"); !w.ok()) {
    return Fail("interpolate", w);
  }
  if (a.Has("schedule")) {
    // One output, its weights per frame from the schedule's keyframes.
    if (a.Has("weights")) {
      return Fail("interpolate", absl::InvalidArgumentError("give --weights or --schedule, not both"));
    }
    std::ifstream in(a.Get("schedule"));
    if (!in) {
      return Fail("interpolate", absl::NotFoundError(absl::StrCat("--schedule ", a.Get("schedule"),
                                                                  ": cannot open")));
    }
    std::stringstream text;
    text << in.rdbuf();
    auto schedule = stylus::ParseSchedule(text.str(), a.Get("schedule"),
                                          static_cast<int>(styles.size()), content->num_frames);
    if (!schedule.ok()) return Fail("interpolate", schedule.status());
    auto out = client.Interpolate(*content, styles, {}, *schedule, *opts);
    if (!out.ok()) return Fail("interpolate", out.status());
    const std::string path = prefix + extension;
    if (absl::Status s = Write(*out, path, a); !s.ok()) return Fail("interpolate", s);
    absl::PrintF("wrote %s (weights per frame from %s)\n", path, a.Get("schedule"));
    return 0;
  }
  std::vector<std::vector<double>> mixes;
  for (absl::string_view group : absl::StrSplit(a.Get("weights"), ',', absl::SkipEmpty())) {
    std::vector<double> mix;
    for (absl::string_view w : absl::StrSplit(group, ':')) {
      double v;
      if (!absl::SimpleAtod(w, &v)) {
        return Fail("interpolate", absl::InvalidArgumentError(
                                       absl::StrCat("--weights: '", w, "' is not a number")));
      }
      mix.push_back(v);
    }
    if (mix.size() == 1 && styles.size() == 2) mix = {1 - mix[0], mix[0]};
    if (mix.size() != styles.size()) {
      return Fail("interpolate", absl::InvalidArgumentError(
                                     absl::StrCat("--weights: group '", group, "' has ", mix.size(),
                                                  " weights for ", styles.size(), " styles")));
    }
    mixes.push_back(mix);
  }
  if (mixes.empty()) {
    return Fail("interpolate", absl::InvalidArgumentError(
                                   "--weights (e.g. 0,0.5,1) or --schedule FILE is required"));
  }
  for (size_t i = 0; i < mixes.size(); ++i) {
    auto out = client.Interpolate(*content, styles, mixes[i], {}, *opts);
    if (!out.ok()) return Fail("interpolate", out.status());
    const std::string path = absl::StrCat(prefix, "_", i, extension);
    if (absl::Status s = Write(*out, path, a); !s.ok()) {
      return Fail("interpolate", s);
    }
    std::vector<std::string> w;
    for (double v : mixes[i]) w.push_back(absl::StrFormat("%g", v));
    absl::PrintF("wrote %s (weights %s)\n", path, absl::StrJoin(w, ":"));
  }
  return 0;
}

int Stream(stylus::Client& client, const Args& a) {
  auto opts = Common(a);
  if (!opts.ok()) return Fail("stream", opts.status());
  auto content = Read(a.Get("content"), "content", a);
  if (!content.ok()) return Fail("stream", content.status());
  std::optional<stylus::motion::Motion> style_clip;
  absl::StatusOr<stylus::Style> ref = StyleArg(a, *opts, *content, &style_clip);
  if (!ref.ok()) return Fail("stream", ref.status());
  if (!a.Get("out").empty()) {
    if (absl::Status w = CheckWritable(a.Get("out"), "-o"); !w.ok()) return Fail("stream", w);
  }
  auto rate = a.GetDouble("rate", content->fps());
  if (!rate.ok() || *rate < 0) {
    return Fail("stream", absl::InvalidArgumentError("--rate must be a number >= 0"));
  }
  if (*rate > 0 && std::abs(*rate - content->fps()) > 0.01 * content->fps()) {
    // The frames keep the clip's own rate; --rate only paces the sending.
    absl::FPrintF(stderr,
                  "stylus stream: note: the clip was recorded at %.4g fps and is sent at %.4g "
                  "fps: it plays %.2fx %s than recorded (the server reads it at %.4g fps)\n",
                  content->fps(), *rate,
                  *rate < content->fps() ? content->fps() / *rate : *rate / content->fps(),
                  *rate < content->fps() ? "slower" : "faster", content->fps());
  }
  // --change FRAME:WHAT[:FADE]; WHAT is a .bvh clip, strength=K or a saved name.
  std::vector<stylus::StreamChange> changes;
  std::vector<std::unique_ptr<stylus::motion::Motion>> change_clips;
  for (const std::string& spec : a.All("change")) {
    const std::vector<std::string> parts = absl::StrSplit(spec, ':');
    stylus::StreamChange c;
    double k = 0;
    const auto bad = [&spec](const std::string& why) {
      return absl::InvalidArgumentError(
          absl::StrCat("--change ", spec, ": ", why, " (FRAME:STYLE.bvh|NAME|strength=K[:FADE])"));
    };
    if (parts.size() < 2 || parts.size() > 3 || !absl::SimpleAtoi(parts[0], &c.frame)) {
      return Fail("stream", bad("expected FRAME:WHAT[:FADE]"));
    }
    if (parts.size() == 3 && (!absl::SimpleAtoi(parts[2], &c.fade_frames) || c.fade_frames < 0)) {
      return Fail("stream", bad("the fade must be a number of frames >= 0"));
    }
    const std::string& what = parts[1];
    if (absl::StartsWith(what, "strength=")) {
      if (!absl::SimpleAtod(what.substr(9), &k) || k < 0 || k > 1) {
        return Fail("stream", bad("strength must be in [0, 1]"));
      }
      c.strength = k;
    } else if (IsClipPath(what)) {
      auto clip = Read(what, "style change", a);
      if (!clip.ok()) return Fail("stream", clip.status());
      change_clips.push_back(std::make_unique<stylus::motion::Motion>(*std::move(clip)));
      c.style.clip = change_clips.back().get();
    } else {
      c.style.name = what;
    }
    changes.push_back(std::move(c));
  }
  auto result = client.Stream(*content, *ref, *rate, *opts, changes);
  if (!result.ok()) return Fail("stream", result.status());
  if (!a.Get("out").empty()) {
    if (absl::Status s = Write(result->output, a.Get("out"), a); !s.ok()) {
      return Fail("stream", s);
    }
  }
  absl::PrintF("streamed %d frames at %.1f fps; got %d back; latency p50 %.1f ms, p99 %.1f ms\n",
               content->num_frames, *rate, result->output.num_frames,
               1000 * Percentile(result->latency_s, 0.5),
               1000 * Percentile(result->latency_s, 0.99));
  return 0;
}

int Metrics(stylus::Client& client, const Args& a) {
  auto output = Read(a.Get("output"), "output", a);
  if (!output.ok()) return Fail("metrics", output.status());
  absl::StatusOr<stylus::motion::Motion> content, style;
  if (a.Has("content")) {
    content = Read(a.Get("content"), "content", a);
    if (!content.ok()) return Fail("metrics", content.status());
  }
  if (a.Has("style")) {
    style = Read(a.Get("style"), "style", a);
    if (!style.ok()) return Fail("metrics", style.status());
  }
  auto m = client.ComputeMetrics(*output, a.Has("content") ? &*content : nullptr,
                                 a.Has("style") ? &*style : nullptr);
  if (!m.ok()) return Fail("metrics", m.status());
  std::string json = "{";
  for (const auto& [k, v] : *m) {
    absl::StrAppendFormat(&json, "%s\"%s\": %.6g", json.size() > 1 ? ", " : "", k, v);
  }
  absl::PrintF("%s}\n", json);
  return 0;
}

int EncodeStyle(stylus::Client& client, const Args& a) {
  auto opts = Common(a);
  if (!opts.ok()) return Fail("encode-style", opts.status());
  auto style = Read(a.Get("style"), "style", a);
  if (!style.ok()) return Fail("encode-style", style.status());
  auto code = client.EncodeStyle(*style, a.Get("save-as"), *opts);
  if (!code.ok()) return Fail("encode-style", code.status());
  absl::PrintF("%d values%s\n", code->size(),
               a.Has("save-as") ? absl::StrCat("; saved as '", a.Get("save-as"), "'") : "");
  return 0;
}

// Converts between file formats on this machine (no server): a scene file
// to BVH for tools that read only BVH, or any clip to glTF for a viewer.
int Convert(stylus::Client&, const Args& a) {
  if (a.Get("in").empty() || a.Get("out").empty()) {
    return Fail("convert", absl::InvalidArgumentError("--in FILE and -o FILE are required"));
  }
  if (absl::Status w = CheckWritable(a.Get("out"), "-o"); !w.ok()) return Fail("convert", w);
  auto clip = Read(a.Get("in"), "in", a);
  if (!clip.ok()) return Fail("convert", clip.status());
  stylus::formats::WriteOptions options;
  options.like = a.Get("in");
  if (absl::Status s = stylus::formats::WriteMotionFile(*clip, a.Get("out"), options); !s.ok()) {
    return Fail("convert", s);
  }
  absl::PrintF("wrote %s: %d joints, %d frames at %g fps\n", a.Get("out"),
               clip->skeleton.num_joints(), clip->num_frames, clip->fps());
  return 0;
}

struct Command {
  const char* name;
  const char* summary;
  const char* usage;  // Its options, after "usage: stylus NAME ".
  std::set<std::string> options;
  bool call_options;  // Takes --model and --postprocess.
  int (*run)(stylus::Client&, const Args&);
};

const std::vector<Command>& Commands() {
  static const std::vector<Command>* commands = new std::vector<Command>{
      {"health",
       "SERVING or NOT_SERVING (exit 0 or 1), the server's gRPC health",
       "",
       {},
       false,
       [](stylus::Client& c, const Args&) { return Health(c); }},
      {"models",
       "list the server's models",
       "",
       {},
       false,
       [](stylus::Client& c, const Args&) { return Models(c); }},
      {"model-info",
       "one model (default: the server's default)",
       "[--model M]",
       {"model"},
       false,
       ModelInfo},
      {"load",
       "load models/NAME/VERSION on the server",
       "--model NAME/VERSION",
       {"model"},
       false,
       Load},
      {"unload", "unload a model", "--model NAME/VERSION", {"model"}, false, Unload},
      {"transfer",
       "restyle a clip",
       "--content C.bvh (--style S.bvh | --style-name N) -o OUT.bvh [--timing content|style]\n"
       "         [--fit-frames N]\n\n"
       "  --timing style           the output takes the style's pace: with a package whose\n"
       "                           movement comes from examples (the default), the\n"
       "                           content's path at the example's speed, else the style's\n"
       "                           cadence by a uniform time warp (0.5-2x; its length\n"
       "                           changes); a clip whose motion does not repeat keeps\n"
       "                           the content's timing\n"
       "  --fit-frames N           exactly N output frames (0.5-2x the content's)",
       {"content", "style", "style-name", "out", "timing", "fit-frames"},
       true,
       Transfer},
      {"interpolate",
       "restyle a clip with blends of styles",
       "--content C.bvh --style A --style B [--style ...] (--weights W | --schedule FILE)\n"
       "       -o PREFIX[.EXT]\n\n"
       "  --style A                a style clip (A.bvh, .fbx, .glb...) or a saved style's name\n"
       "  -o PREFIX[.EXT]          writes PREFIX_0.EXT, PREFIX_1.EXT... (EXT: bvh, gltf\n"
       "                           or glb; default bvh); with --schedule, PREFIX.EXT\n"
       "  --schedule FILE          weights that change over the clip: keyframe lines\n"
       "                           'FRAME W1 W2 ...' (one weight per --style), linear\n"
       "                           between keyframes, held before the first and after\n"
       "                           the last; '#' starts a comment\n"
       "  --weights 0,0.5,1        one output per weight of the first style against\n"
       "                           the second (two styles), or\n"
       "  --weights w1:w2:...,...  one mix per comma-separated group",
       {"content", "style", "out", "weights", "schedule"},
       true,
       Interpolate},
      {"stream",
       "stream a clip's frames at a rate; per-frame latency p50/p99",
       "--content C.bvh (--style S.bvh | --style-name NAME) [--rate FPS]\n"
       "       [--change F:WHAT[:FADE]]... [-o OUT.bvh]\n\n"
       "  --style-name NAME        a style saved with encode-style --save-as on this\n"
       "                           model (saved names belong to one model)\n"
       "  --rate FPS               frames sent per second (default: the clip's rate;\n"
       "                           the frames keep the clip's rate, so another --rate\n"
       "                           plays it slower or faster, and says so)\n"
       "  --change F:WHAT[:FADE]   from frame F on, change the style (live models):\n"
       "                           WHAT is a style clip (.bvh, .glb...), a saved name or\n"
       "                           strength=K (0..1), cross-faded over FADE frames\n"
       "                           (default 0); repeat in frame order",
       {"content", "style", "style-name", "rate", "out", "change"},
       true,
       Stream},
      {"metrics",
       "kinematic and style metrics of a clip (JSON)",
       "--output O.bvh [--content C.bvh] [--style S.bvh]",
       {"output", "content", "style", "animation"},
       false,
       Metrics},
      {"convert",
       "convert a clip between formats on this machine (no server)",
       "--in FILE -o OUT [--animation NAME]\n\n"
       "  --in FILE                a .bvh, .fbx, .gltf, .glb or .dae clip\n"
       "  -o OUT                   a .bvh, .gltf or .glb file (a glTF of a scene file\n"
       "                           keeps its meshes and skins; of a BVH, a stick figure\n"
       "                           skinned to the skeleton)\n"
       "  --animation NAME         the animation to read from a file with several (the\n"
       "                           error for such a file lists their names)",
       {"in", "out", "animation"},
       false,
       Convert},
      {"encode-style",
       "a style clip's code, optionally saved under a name",
       "--style S.bvh [--save-as NAME] [--model M] [--joint-map FILE]",
       {"style", "save-as", "model", "joint-map", "animation"},
       false,
       EncodeStyle},
  };
  return *commands;
}

std::string CommandList() {
  std::string out;
  for (const Command& c : Commands())
    absl::StrAppendFormat(&out, "  %-14s %s\n", c.name, c.summary);
  return out;
}

// "usage: stylus NAME SYNOPSIS", the summary, then the options the usage
// explains (after its first blank line) and the call options.
void PrintCommandHelp(const Command& c, FILE* f) {
  const std::string usage = c.usage;
  const size_t split = usage.find("\n\n");
  absl::FPrintF(f, "usage: stylus %s %s\n\n%c%s.\n", c.name, usage.substr(0, split),
                absl::ascii_toupper(c.summary[0]), c.summary + 1);
  if (split != std::string::npos) absl::FPrintF(f, "\n%s\n", usage.substr(split + 2));
  if (c.call_options) absl::FPrintF(f, "\n%s", kCallOptions);
  absl::FPrintF(f,
                "\nglobal options: --server ADDR (default $STYLUS_SERVER, else "
                "localhost:50051), --deadline-s S, --token TOKEN (default $STYLUS_TOKEN),\n"
                "--tls-ca FILE|system (default $STYLUS_TLS_CA), --tls-cert FILE, --tls-key FILE\n");
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    absl::FPrintF(stderr, kUsage, CommandList());
    return 2;
  }
  // The command is the first argument that is not a global option or its value.
  const std::set<std::string> global = {"--server", "--deadline-s", "--token",
                                        "--tls-ca", "--tls-cert",   "--tls-key"};
  size_t at = 0;
  while (at < args.size() && global.count(args[at])) at += 2;
  if (at < args.size() && (args[at] == "--help" || args[at] == "-h")) {
    absl::PrintF(kUsage, CommandList());
    return 0;
  }
  if (at >= args.size()) {
    absl::FPrintF(stderr, "stylus: no command\n\n");
    absl::FPrintF(stderr, kUsage, CommandList());
    return 2;
  }
  const std::string name = args[at];
  const Command* command = nullptr;
  for (const Command& c : Commands()) {
    if (name == c.name) command = &c;
  }
  if (command == nullptr) {
    absl::FPrintF(stderr, "stylus: unknown command '%s'\n\n", name);
    absl::FPrintF(stderr, kUsage, CommandList());
    return 2;
  }
  std::vector<std::string> rest(args.begin(), args.begin() + at);
  rest.insert(rest.end(), args.begin() + at + 1, args.end());
  stylus::cli::ArgSpec spec{command->options, {}};
  spec.options.insert({"server", "deadline-s", "token", "tls-ca", "tls-cert", "tls-key"});
  if (command->call_options) {
    spec.options.insert({"model", "postprocess", "joint-map", "animation"});
  }
  absl::StatusOr<Args> a = stylus::cli::ParseArgs(rest, spec);
  if (!a.ok()) {
    absl::FPrintF(stderr, "stylus %s: %s\n\n", name, a.status().message());
    PrintCommandHelp(*command, stderr);
    return 2;
  }
  if (a->help) {
    PrintCommandHelp(*command, stdout);
    return 0;
  }
  if (!a->positional.empty()) {
    absl::FPrintF(stderr, "stylus %s: unexpected argument '%s'\n\n", name, a->positional[0]);
    PrintCommandHelp(*command, stderr);
    return 2;
  }
  stylus::ClientOptions options;
  const char* env_server = std::getenv("STYLUS_SERVER");
  if (env_server != nullptr && *env_server != '\0') options.address = env_server;
  if (a->Has("server")) options.address = a->Get("server");
  server_address = options.address;
  const char* env_token = std::getenv("STYLUS_TOKEN");
  if (env_token != nullptr) options.token = env_token;
  if (a->Has("token")) options.token = a->Get("token");
  const char* env_ca = std::getenv("STYLUS_TLS_CA");
  std::string ca = a->Has("tls-ca") ? a->Get("tls-ca") : (env_ca != nullptr ? env_ca : "");
  const bool system_ca = ca == "system";
  absl::StatusOr<stylus::TlsOptions> tls =
      stylus::ReadTlsFiles(system_ca ? "" : ca, a->Get("tls-cert"), a->Get("tls-key"));
  if (!tls.ok()) {
    absl::FPrintF(stderr, "stylus %s: %s\n", name, tls.status().message());
    return 2;
  }
  options.tls = *std::move(tls);
  options.tls.enabled = options.tls.enabled || system_ca;
  if (a->Has("deadline-s")) {
    double s;
    if (!absl::SimpleAtod(a->Get("deadline-s"), &s) || !(s > 0)) {
      absl::FPrintF(stderr, "stylus %s: --deadline-s needs a positive number\n", name);
      return 2;
    }
    options.deadline = std::chrono::milliseconds(static_cast<int64_t>(s * 1000));
  }
  stylus::Client client(options);
  return command->run(client, *a);
}
