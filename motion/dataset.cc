#include "motion/dataset.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace stylus::motion {

namespace fs = std::filesystem;

uint64_t StableHash(absl::string_view s, uint64_t seed) {
  uint64_t h = 1469598103934665603ull ^ (seed * 0x9E3779B97F4A7C15ull);
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::optional<ClipLabel> ParseClipName(absl::string_view path) {
  const size_t slash = path.find_last_of('/');
  absl::string_view name = slash == absl::string_view::npos ? path : path.substr(slash + 1);
  if (!absl::ConsumeSuffix(&name, ".bvh")) return std::nullopt;
  std::vector<absl::string_view> parts = absl::StrSplit(name, '_');
  ClipLabel l;
  if (parts.size() != 4 || !absl::StartsWith(parts[0], "dataset-") || parts[1].empty() ||
      parts[2].empty() || !absl::SimpleAtoi(parts[3], &l.take) || l.take < 0) {
    return std::nullopt;
  }
  l.dataset = std::string(parts[0]);
  l.content = std::string(parts[1]);
  l.style = std::string(parts[2]);
  return l;
}

std::vector<std::string> DatasetIndex::Contents() const {
  std::set<std::string> s;
  for (const ClipEntry& c : clips) s.insert(c.label.content);
  return {s.begin(), s.end()};
}

std::vector<std::string> DatasetIndex::Styles() const {
  std::set<std::string> s;
  for (const ClipEntry& c : clips) s.insert(c.label.style);
  return {s.begin(), s.end()};
}

std::vector<const ClipEntry*> DatasetIndex::Split(bool test) const {
  std::vector<const ClipEntry*> out;
  for (const ClipEntry& c : clips) {
    if (c.test == test) out.push_back(&c);
  }
  return out;
}

absl::StatusOr<DatasetIndex> IndexDataset(const std::vector<std::string>& dirs,
                                          const SplitOptions& options) {
  DatasetIndex index;
  for (const std::string& dir : dirs) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
      return absl::NotFoundError(absl::StrCat(dir, ": not a directory"));
    }
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
         it.increment(ec)) {
      if (!it->is_regular_file() || it->path().extension() != ".bvh") continue;
      const std::string path = it->path().string();
      std::optional<ClipLabel> label = ParseClipName(path);
      if (!label) {
        index.skipped.push_back(path + ": name is not dataset-N_content_style_take.bvh");
        continue;
      }
      index.clips.push_back({path, *label, false});
    }
    if (ec) return absl::InternalError(absl::StrCat(dir, ": ", ec.message()));
  }
  if (index.clips.empty()) {
    return absl::NotFoundError("no labelled .bvh clips found under the given directories");
  }
  std::sort(index.clips.begin(), index.clips.end(),
            [](const ClipEntry& a, const ClipEntry& b) { return a.path < b.path; });

  // Groups of many takes of one (dataset, content, style): hold out takes chosen by
  // hash. Contents with few takes per style: hold out the clips of the styles
  // held out least so far, so every style is held out about equally often.
  std::map<std::string, std::vector<ClipEntry*>> by_style;
  for (ClipEntry& c : index.clips) {
    by_style[absl::StrCat(c.label.dataset, "/", c.label.content, "/", c.label.style)].push_back(&c);
  }
  auto held_count = [&](int n) {
    if (n < 2 || options.test_fraction <= 0) return 0;
    return std::min(n - 1, std::max(1, static_cast<int>(std::lround(options.test_fraction * n))));
  };
  auto by_hash = [&](std::vector<ClipEntry*>* members, auto key) {
    std::sort(members->begin(), members->end(), [&](const ClipEntry* a, const ClipEntry* b) {
      return StableHash(key(a), options.seed) < StableHash(key(b), options.seed);
    });
  };
  auto file_name = [](const ClipEntry* c) { return fs::path(c->path).filename().string(); };
  std::map<std::string, std::vector<ClipEntry*>> few_takes;  // dataset/content -> clips
  for (auto& [key, members] : by_style) {
    if (members.size() < 5) {
      const std::string content_key = key.substr(0, key.find_last_of('/'));
      for (ClipEntry* c : members) few_takes[content_key].push_back(c);
      continue;
    }
    by_hash(&members, file_name);
    for (int i = 0; i < held_count(static_cast<int>(members.size())); ++i) members[i]->test = true;
  }
  std::map<std::string, int> times_held;  // "dataset/style" -> clips held out so far.
  for (auto& [key, members] : few_takes) {
    // Least-held styles first; ties by hash of the file name.
    by_hash(&members, file_name);
    std::stable_sort(members.begin(), members.end(), [&](const ClipEntry* a, const ClipEntry* b) {
      return times_held[a->label.dataset + "/" + a->label.style] <
             times_held[b->label.dataset + "/" + b->label.style];
    });
    const int held = held_count(static_cast<int>(members.size()));
    for (int i = 0; i < held; ++i) {
      members[i]->test = true;
      ++times_held[members[i]->label.dataset + "/" + members[i]->label.style];
    }
  }
  return index;
}

std::optional<std::string> FindBandaiData(const std::string& project_root) {
  std::string dir;
  if (const char* env = std::getenv("STYLUS_DATA"); env != nullptr && env[0] != '\0') {
    dir = env;
  } else {
    dir = project_root + "/../shared/data/bandai";
  }
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return std::nullopt;
  return fs::weakly_canonical(dir, ec).string();
}

std::string CanonicalPath(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : p.string();
}

absl::StatusOr<std::map<std::string, ClipLabel>> ReadLabelsCsv(const std::string& csv) {
  std::map<std::string, ClipLabel> labels;
  if (csv.empty()) return labels;
  std::ifstream in(csv);
  if (!in) return absl::NotFoundError(csv + ": cannot open the labels file");
  const std::filesystem::path dir = std::filesystem::path(csv).parent_path();
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const absl::string_view l = absl::StripAsciiWhitespace(line);
    if (l.empty() || l[0] == '#' || (n == 1 && absl::StartsWith(l, "clip,"))) continue;
    std::vector<std::string> cols = absl::StrSplit(l, ',');
    if (cols.size() != 3 || cols[0].empty() || cols[1].empty() || cols[2].empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat(csv, ":", n, ": expected clip,content,style (e.g. take1.bvh,walk,angry)"));
    }
    for (std::string& c : cols) c = std::string(absl::StripAsciiWhitespace(c));
    const std::filesystem::path clip = std::filesystem::path(cols[0]).is_absolute()
                                           ? std::filesystem::path(cols[0])
                                           : dir / cols[0];
    ClipLabel label;
    label.dataset = "labels";
    label.content = cols[1];
    label.style = cols[2];
    labels[CanonicalPath(clip.string())] = label;
  }
  return labels;
}

}  // namespace stylus::motion
