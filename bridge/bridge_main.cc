// stylus-bridge: see bridge/bridge.h and docs/stage.md.
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "bridge/bridge.h"
#include "bridge/console.h"
#include "bridge/cues.h"
#include "cli/args.h"
#include "formats/scene_file.h"
#include "motion/rig_roles.h"
#include "spdlog/spdlog.h"

namespace {

constexpr char kHelp[] =
    "usage: stylus-bridge --vmc-out HOST:PORT[,HOST:PORT...] (--style CLIP | --style-name NAME)\n"
    "                     [--vmc-in PORT] [--server ADDR] [--model M] [--fps N] [--hold]\n"
    "                     [--fade-frames N] [--postprocess default|none|feet|full] [--stats S]\n"
    "                     [--console HOST:PORT] [--three-js PATH] [--cues FILE]\n"
    "       stylus-bridge --bvh-skeleton FILE (--bvh-in HOST:PORT | --bvh-in-udp PORT)\n"
    "                     (--bvh-out PORT | --bvh-out-udp HOST:PORT) (--style CLIP | ...) [...]\n\n"
    "Sits between a mocap stage and the engine: reads the VMC protocol (OSC over\n"
    "UDP) from capture software as a Marionette, streams each performer (by\n"
    "source address) through a Stylus server, and sends the stylized motion on\n"
    "as a Performer to the engine's VMC receiver (Unity EVMC4U, Unreal VMC4UE,\n"
    "Blender VMC4B, Godot). Or reads BVH broadcast as Axis Neuron / Axis Studio\n"
    "send it (each avatar a performer) and serves it on to engines' Neuron\n"
    "plug-ins in the same form. If the server restarts or a stream fails, the\n"
    "performer's own motion passes through (or, with --hold, the last output\n"
    "holds) while the bridge reconnects, then the style fades back in.\n\n"
    "  --vmc-in PORT        where performers send (default 39539)\n"
    "  --vmc-out ADDRS      the engine's receiver per performer, in the order\n"
    "                       performers first send (the last serves any more)\n"
    "  --bvh-in HOST:PORT   BVH broadcast, text form (TCP): the capture software's\n"
    "                       broadcast port (Axis Neuron's default 7001); the\n"
    "                       bridge connects, and again whenever it is lost\n"
    "  --bvh-in-udp PORT    BVH broadcast, binary form: the UDP port to listen on\n"
    "  --bvh-skeleton FILE  the performers' skeleton, a BVH file exported from the\n"
    "                       capture software (the stream carries values only)\n"
    "  --joint-map FILE     that skeleton's humanoid roles where its joint names\n"
    "                       don't say them: lines like 'left_foot = MyFootL'\n"
    "  --bvh-out PORT       serve the stylized BVH broadcast (text form) on this\n"
    "                       TCP port, to every engine that connects\n"
    "  --bvh-out-udp HOST:PORT  send it in the binary form to this UDP address\n"
    "  --style CLIP         a style clip (.bvh, .fbx, .gltf, .glb, .dae), or\n"
    "  --style-name NAME    a style saved on the server for the model\n"
    "  --model M            default live (a live model: frames come back two\n"
    "                       frames after they went in)\n"
    "  --fps N              the performers' frame rate (default 60)\n"
    "  --fade-frames N      fades back to the style and between styles (default 15)\n"
    "  --stats S            print the counters every S seconds\n"
    "  --max-performers N   sources taken at most, each a stream (default 32);\n"
    "                       frames from further sources are counted and dropped\n"
    "  --cues FILE          style changes in time: lines 'SECONDS style NAME-OR-CLIP'\n"
    "                       or 'SECONDS strength K', seconds from the start\n"
    "  --console HOST:PORT  serve the stage console (a web page: the performer and\n"
    "                       the stylized output side by side, style picker,\n"
    "                       strength slider, latency and counters), e.g.\n"
    "                       0.0.0.0:8080 for the stage's network\n"
    "  --three-js PATH      three.min.js for the console (default Debian's\n"
    "                       /usr/share/javascript/three/three.min.js)\n\n"
    "Live control (OSC, to --vmc-in): /stylus/style s (a saved name or a clip\n"
    "path), /stylus/strength f (0..1); each fades over --fade-frames.\n\n"
    "global options: --server ADDR (default $STYLUS_SERVER, else localhost:50051),\n"
    "--token TOKEN (default $STYLUS_TOKEN), --tls-ca FILE|system\n";

volatile std::sig_atomic_t stop = 0;
void OnSignal(int) { stop = 1; }

int Fail(const std::string& what) {
  std::fprintf(stderr, "stylus-bridge: %s\n", what.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using stylus::cli::ParseArgs;
  const std::vector<std::string> args(argv + 1, argv + argc);
  stylus::cli::ArgSpec spec{
      {"vmc-in",       "vmc-out",    "server",      "token",          "tls-ca",      "model",
       "style",        "style-name", "fps",         "fade-frames",    "postprocess", "stats",
       "console",      "three-js",   "cues",        "max-performers", "bvh-in",      "bvh-in-udp",
       "bvh-skeleton", "bvh-out",    "bvh-out-udp", "joint-map"},
      {"hold"}};
  absl::StatusOr<stylus::cli::Args> a = ParseArgs(args, spec);
  if (!a.ok()) {
    std::fprintf(stderr, "stylus-bridge: %s\n\n%s", std::string(a.status().message()).c_str(), kHelp);
    return 2;
  }
  if (a->help) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  stylus::bridge::BridgeOptions o;
  absl::StatusOr<int> port = a->GetInt("vmc-in", 39539);
  absl::StatusOr<double> fps = a->GetDouble("fps", 60);
  absl::StatusOr<int> fade = a->GetInt("fade-frames", 15);
  absl::StatusOr<double> every = a->GetDouble("stats", 0);
  absl::StatusOr<int> max_performers = a->GetInt("max-performers", 32);
  if (!max_performers.ok()) return Fail(std::string(max_performers.status().message()));
  if (*max_performers < 1 || *max_performers > 1024) return Fail("--max-performers wants 1 to 1024");
  o.max_performers = *max_performers;
  for (const absl::Status& s : {port.status(), fps.status(), fade.status(), every.status()}) {
    if (!s.ok()) return Fail(std::string(s.message()));
  }
  if (*port < 0 || *port > 65535) return Fail("--vmc-in wants a port 0-65535");
  if (!(*fps >= 1 && *fps <= 1000)) return Fail("--fps wants a rate of 1 to 1000 frames per second");
  o.vmc_in_port = *port;
  o.fps = *fps;
  o.fade_frames = std::max(0, *fade);
  o.hold = a->switches.count("hold") > 0;
  o.model = a->Get("model", "live");
  for (absl::string_view out : absl::StrSplit(a->Get("vmc-out"), ',', absl::SkipEmpty())) {
    o.vmc_out.emplace_back(out);
  }
  o.bvh_in = a->Get("bvh-in");
  o.bvh_out_udp = a->Get("bvh-out-udp");
  for (const char* name : {"bvh-in-udp", "bvh-out"}) {
    if (!a->Has(name)) continue;
    absl::StatusOr<int> p = a->GetInt(name, 0);
    if (!p.ok()) return Fail(std::string(p.status().message()));
    if (*p < 0 || *p > 65535) return Fail(std::string("--") + name + " wants a port 0-65535");
    (std::string(name) == "bvh-out" ? o.bvh_out_port : o.bvh_in_udp) = *p;
  }
  if (a->Has("bvh-skeleton")) {
    absl::StatusOr<stylus::motion::Motion> sk =
        stylus::formats::ReadMotionFile(a->Get("bvh-skeleton"));
    if (!sk.ok()) return Fail(std::string(sk.status().message()));
    o.bvh_skeleton = sk->skeleton;
  }
  if (a->Has("joint-map")) {
    absl::StatusOr<stylus::motion::JointMap> map =
        stylus::motion::ReadJointMapFile(a->Get("joint-map"));
    if (!map.ok()) return Fail(std::string(map.status().message()));
    if (!a->Has("bvh-skeleton"))
      return Fail("--joint-map is for the --bvh-skeleton rig (VMC bones are Unity's)");
    o.bvh_joint_map = *std::move(map);
  }
  absl::StatusOr<stylus::v1::PostProcess> post =
      stylus::ParsePostProcess(a->Get("postprocess", "default"));
  if (!post.ok()) return Fail(std::string(post.status().message()));
  o.postprocess = *post;
  if (a->Has("style") == a->Has("style-name")) {
    return Fail("give the style: --style CLIP or --style-name NAME (one of them)");
  }
  if (a->Has("style")) {
    absl::StatusOr<stylus::motion::Motion> clip = stylus::formats::ReadMotionFile(a->Get("style"));
    if (!clip.ok()) return Fail(std::string(clip.status().message()));
    o.style_clip = *std::move(clip);
    o.style_label = a->Get("style");
  } else {
    o.style_name = a->Get("style-name");
  }
  const char* env_server = std::getenv("STYLUS_SERVER");
  if (env_server != nullptr && *env_server != '\0') o.client.address = env_server;
  if (a->Has("server")) o.client.address = a->Get("server");
  const char* env_token = std::getenv("STYLUS_TOKEN");
  if (env_token != nullptr) o.client.token = env_token;
  if (a->Has("token")) o.client.token = a->Get("token");
  if (a->Has("tls-ca")) {
    const bool system = a->Get("tls-ca") == "system";
    absl::StatusOr<stylus::TlsOptions> tls =
        stylus::ReadTlsFiles(system ? "" : a->Get("tls-ca"), "", "");
    if (!tls.ok()) return Fail(std::string(tls.status().message()));
    o.client.tls = *std::move(tls);
    o.client.tls.enabled = true;
  }

  std::vector<stylus::bridge::Cue> cues;
  if (a->Has("cues")) {
    std::ifstream in(a->Get("cues"));
    if (!in) return Fail(a->Get("cues") + ": cannot open");
    std::stringstream text;
    text << in.rdbuf();
    absl::StatusOr<std::vector<stylus::bridge::Cue>> parsed =
        stylus::bridge::ParseCues(text.str(), a->Get("cues"));
    if (!parsed.ok()) return Fail(std::string(parsed.status().message()));
    cues = *std::move(parsed);
  }
  stylus::bridge::Bridge bridge(o);
  if (absl::Status s = bridge.Start(); !s.ok()) return Fail(std::string(s.message()));
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  spdlog::info("listening for VMC and live control on UDP {}; streaming through {} ({})",
               bridge.port(), o.client.address, o.model);
  if (bridge.bvh_out_port() >= 0)
    spdlog::info("serving BVH broadcast on TCP {}", bridge.bvh_out_port());
  if (bridge.bvh_in_udp_port() >= 0) {
    spdlog::info("listening for BVH broadcast (binary) on UDP {}", bridge.bvh_in_udp_port());
  }
  std::unique_ptr<stylus::bridge::Console> console;
  if (a->Has("console")) {
    console = std::make_unique<stylus::bridge::Console>(
        &bridge, a->Get("three-js", "/usr/share/javascript/three/three.min.js"));
    if (absl::Status s = console->Start(a->Get("console")); !s.ok()) {
      bridge.Stop();
      return Fail(std::string(s.message()));
    }
    spdlog::info("stage console on http://{}/ (port {})", a->Get("console"), console->port());
  }
  auto last = std::chrono::steady_clock::now();
  const auto started = last;
  size_t next_cue = 0;
  while (!stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const double now_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    for (; next_cue < cues.size() && cues[next_cue].seconds <= now_s; ++next_cue) {
      const stylus::bridge::Cue& cue = cues[next_cue];
      if (cue.strength) {
        bridge.ChangeStrength(cue.value);
      } else {
        bridge.ChangeStyle(cue.style);
      }
    }
    if (*every > 0 && std::chrono::steady_clock::now() - last >= std::chrono::duration<double>(*every)) {
      last = std::chrono::steady_clock::now();
      const stylus::bridge::BridgeStats st = bridge.stats();
      absl::PrintF(
          "performers %d received %d styled %d passed %d held %d out_of_order %d malformed %d "
          "stream_failures %d reconnects %d refused %d engine_drops %d added_us_p50 %.0f "
          "added_us_p99 %.0f\n",
          st.performers, st.received, st.styled, st.passed, st.held, st.out_of_order, st.malformed,
          st.stream_failures, st.reconnects, st.refused, st.engine_drops, st.added_p50_us,
          st.added_p99_us);
      std::fflush(stdout);
    }
  }
  if (console) console->Stop();
  bridge.Stop();
  return 0;
}
