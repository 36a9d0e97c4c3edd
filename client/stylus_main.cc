// stylus: the command-line client of a Stylus server.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "absl/strings/numbers.h"
#include "client/client.h"
#include "motion/bvh.h"
#include "tool/args.h"

namespace {

using stylus::tool::Args;

constexpr char kUsage[] =
    "usage: stylus [--server ADDR] [--deadline-s S] COMMAND [options]\n\n"
    "Calls a Stylus server (default localhost:50051).\n\n"
    "commands:\n"
    "  models                                   list the server's models\n"
    "  model-info [--model M]                   one model (default: the default)\n"
    "  load --model NAME/VERSION                load models/NAME/VERSION on the server\n"
    "  unload --model NAME/VERSION              unload it\n"
    "  transfer --content C.bvh (--style S.bvh | --style-name N) -o OUT.bvh\n"
    "  interpolate --content C.bvh --style A.bvh --style B.bvh [--style ...]\n"
    "              --weights 0,0.5,1 -o PREFIX  one output per weight of the\n"
    "              first style against the second (two styles), or\n"
    "              --weights w1:w2:...,...  one mix per comma-separated group\n"
    "  stream --content C.bvh --style S.bvh [--rate 30] -o OUT.bvh\n"
    "                                           streams frames at --rate fps,\n"
    "                                           prints per-frame latency p50/p99\n"
    "  metrics --output O.bvh [--content C.bvh] [--style S.bvh]   JSON\n"
    "  encode-style --style S.bvh [--save-as NAME]\n\n"
    "common options: --model NAME[/VERSION] (default: the server's default)\n"
    "                --postprocess default|none|feet|full\n"
    "Run `stylus COMMAND --help` for a command's options.\n";

int Fail(const std::string& command, const absl::Status& status) {
  std::fprintf(stderr, "stylus %s: %s: %s\n", command.c_str(),
               absl::StatusCodeToString(status.code()).c_str(),
               std::string(status.message()).c_str());
  return 1;
}

absl::StatusOr<stylus::motion::Motion> Read(const std::string& path, const std::string& what) {
  if (path.empty()) return absl::InvalidArgumentError(absl::StrCat("--", what, " is required"));
  return stylus::motion::ReadBvhFile(path);
}

absl::StatusOr<stylus::CallOptions> Common(const Args& a) {
  stylus::CallOptions o;
  o.model = a.Get("model");
  const std::string p = a.Get("postprocess", "default");
  if (p == "default") {
    o.postprocess = stylus::v1::POSTPROCESS_DEFAULT;
  } else if (p == "none") {
    o.postprocess = stylus::v1::POSTPROCESS_NONE;
  } else if (p == "feet") {
    o.postprocess = stylus::v1::POSTPROCESS_FEET;
  } else if (p == "full") {
    o.postprocess = stylus::v1::POSTPROCESS_FULL;
  } else {
    return absl::InvalidArgumentError("--postprocess must be default, none, feet or full");
  }
  return o;
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
    absl::PrintF("%s%s  family=%s joints=%d fps=%.1f window=%d hop=%d iterations=%d\n", m.id(),
                 m.is_default() ? " (default)" : "", m.family(), m.skeleton().joints_size(), m.fps(),
                 m.window(), m.hop(), m.trained_iterations());
  }
  return 0;
}

int ModelInfo(stylus::Client& client, const Args& a) {
  auto m = client.GetModel(a.Get("model"));
  if (!m.ok()) return Fail("model-info", m.status());
  absl::PrintF("id %s\nfamily %s\nversion %s\ndefault %s\njoints %d\nfps %.3f\nwindow %d\nhop %d\n"
               "trained_iterations %d\n",
               m->id(), m->family(), m->version(), m->is_default() ? "yes" : "no",
               m->skeleton().joints_size(), m->fps(), m->window(), m->hop(),
               m->trained_iterations());
  return 0;
}

int Load(stylus::Client& client, const Args& a) {
  if (a.Get("model").empty()) return Fail("load", absl::InvalidArgumentError("--model is required"));
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
  auto content = Read(a.Get("content"), "content");
  if (!content.ok()) return Fail("transfer", content.status());
  absl::StatusOr<stylus::motion::Motion> style;
  stylus::Style ref;
  if (a.Has("style-name")) {
    ref.name = a.Get("style-name");
  } else {
    style = Read(a.Get("style"), "style");
    if (!style.ok()) return Fail("transfer", style.status());
    ref.clip = &*style;
  }
  if (a.Get("out").empty()) return Fail("transfer", absl::InvalidArgumentError("-o is required"));
  stylus::v1::ContentGuardNote guard;
  opts->content_guard = &guard;
  auto out = client.Transfer(*content, ref, *opts);
  if (!out.ok()) return Fail("transfer", out.status());
  if (absl::Status s = stylus::motion::WriteBvhFile(*out, a.Get("out")); !s.ok()) {
    return Fail("transfer", s);
  }
  absl::PrintF("wrote %s (%d frames)%s\n", a.Get("out"), out->num_frames,
               guard.backed_off()
                   ? absl::StrFormat(" (content guard: the configured transfer read as another "
                                     "action; residual form at strength %g)",
                                     guard.residual_strength())
                   : "");
  return 0;
}

int Interpolate(stylus::Client& client, const Args& a) {
  auto opts = Common(a);
  if (!opts.ok()) return Fail("interpolate", opts.status());
  auto content = Read(a.Get("content"), "content");
  if (!content.ok()) return Fail("interpolate", content.status());
  std::vector<stylus::motion::Motion> clips;
  for (const std::string& p : a.All("style")) {
    auto s = stylus::motion::ReadBvhFile(p);
    if (!s.ok()) return Fail("interpolate", s.status());
    clips.push_back(*std::move(s));
  }
  if (clips.size() < 2) {
    return Fail("interpolate", absl::InvalidArgumentError("give two or more --style clips"));
  }
  std::vector<stylus::Style> styles;
  for (const auto& c : clips) styles.push_back({&c, ""});
  const std::string prefix = a.Get("out");
  if (prefix.empty()) return Fail("interpolate", absl::InvalidArgumentError("-o PREFIX is required"));
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
    if (mix.size() == 1 && clips.size() == 2) mix = {1 - mix[0], mix[0]};
    if (mix.size() != clips.size()) {
      return Fail("interpolate",
                  absl::InvalidArgumentError(absl::StrCat("--weights: group '", group, "' has ",
                                                          mix.size(), " weights for ",
                                                          clips.size(), " styles")));
    }
    mixes.push_back(mix);
  }
  if (mixes.empty()) {
    return Fail("interpolate", absl::InvalidArgumentError("--weights is required, e.g. 0,0.5,1"));
  }
  for (size_t i = 0; i < mixes.size(); ++i) {
    auto out = client.Interpolate(*content, styles, mixes[i], {}, *opts);
    if (!out.ok()) return Fail("interpolate", out.status());
    const std::string path = absl::StrCat(prefix, "_", i, ".bvh");
    if (absl::Status s = stylus::motion::WriteBvhFile(*out, path); !s.ok()) {
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
  auto content = Read(a.Get("content"), "content");
  if (!content.ok()) return Fail("stream", content.status());
  auto style = Read(a.Get("style"), "style");
  if (!style.ok()) return Fail("stream", style.status());
  auto rate = a.GetDouble("rate", content->fps());
  if (!rate.ok() || *rate < 0) {
    return Fail("stream", absl::InvalidArgumentError("--rate must be a number >= 0"));
  }
  auto result = client.Stream(*content, {&*style, ""}, *rate, *opts);
  if (!result.ok()) return Fail("stream", result.status());
  if (!a.Get("out").empty()) {
    if (absl::Status s = stylus::motion::WriteBvhFile(result->output, a.Get("out")); !s.ok()) {
      return Fail("stream", s);
    }
  }
  absl::PrintF("streamed %d frames at %.1f fps; got %d back; latency p50 %.1f ms, p99 %.1f ms\n",
               content->num_frames, *rate, result->output.num_frames,
               1000 * Percentile(result->latency_s, 0.5), 1000 * Percentile(result->latency_s, 0.99));
  return 0;
}

int Metrics(stylus::Client& client, const Args& a) {
  auto output = Read(a.Get("output"), "output");
  if (!output.ok()) return Fail("metrics", output.status());
  absl::StatusOr<stylus::motion::Motion> content, style;
  if (a.Has("content")) {
    content = stylus::motion::ReadBvhFile(a.Get("content"));
    if (!content.ok()) return Fail("metrics", content.status());
  }
  if (a.Has("style")) {
    style = stylus::motion::ReadBvhFile(a.Get("style"));
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
  auto style = Read(a.Get("style"), "style");
  if (!style.ok()) return Fail("encode-style", style.status());
  auto code = client.EncodeStyle(*style, a.Get("save-as"), *opts);
  if (!code.ok()) return Fail("encode-style", code.status());
  absl::PrintF("%d values%s\n", code->size(),
               a.Has("save-as") ? absl::StrCat("; saved as '", a.Get("save-as"), "'") : "");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  stylus::ClientOptions options;
  // Global options come before the command.
  size_t i = 0;
  for (; i < args.size() && args[i].rfind("--", 0) == 0; ++i) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (i + 1 >= args.size()) break;
    if (args[i] == "--server") {
      options.address = args[++i];
    } else if (args[i] == "--deadline-s") {
      double s;
      if (!absl::SimpleAtod(args[++i], &s) || s <= 0) {
        std::fprintf(stderr, "stylus: --deadline-s needs a positive number\n");
        return 2;
      }
      options.deadline = std::chrono::milliseconds(static_cast<int64_t>(s * 1000));
    } else {
      break;
    }
  }
  if (i >= args.size()) {
    std::fprintf(stderr, "stylus: no command\n\n%s", kUsage);
    return 2;
  }
  const std::string command = args[i];
  const std::vector<std::string> rest(args.begin() + i + 1, args.end());
  const stylus::tool::ArgSpec spec{{"content", "style", "style-name", "out", "model", "weights",
                                    "rate", "output", "postprocess", "save-as"},
                                   {}};
  absl::StatusOr<Args> a = stylus::tool::ParseArgs(rest, spec);
  if (!a.ok()) {
    std::fprintf(stderr, "stylus %s: %s\n\n%s", command.c_str(),
                 std::string(a.status().message()).c_str(), kUsage);
    return 2;
  }
  if (a->help) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  stylus::Client client(options);
  if (command == "models") return Models(client);
  if (command == "model-info") return ModelInfo(client, *a);
  if (command == "load") return Load(client, *a);
  if (command == "unload") return Unload(client, *a);
  if (command == "transfer") return Transfer(client, *a);
  if (command == "interpolate") return Interpolate(client, *a);
  if (command == "stream") return Stream(client, *a);
  if (command == "metrics") return Metrics(client, *a);
  if (command == "encode-style") return EncodeStyle(client, *a);
  std::fprintf(stderr, "stylus: unknown command '%s'\n\n%s", command.c_str(), kUsage);
  return 2;
}
