#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "absl/container/flat_hash_set.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "motion/bvh.h"

namespace stylus::motion {
namespace {

struct Token {
  absl::string_view text;  // Empty at end of input.
  int line = 0;
};

bool IsBinaryByte(unsigned char c) {
  return (c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f;
}

// Splits text into whitespace-separated tokens, tracking line numbers. CR, LF
// and CRLF all end a line.
class Lexer {
 public:
  explicit Lexer(absl::string_view text) : text_(text) {}

  // The next token; sets `error_` on binary data.
  Token Next() {
    SkipSpace(/*stop_at_newline=*/false);
    Token t;
    t.line = line_;
    const size_t start = pos_;
    while (pos_ < text_.size() && !IsSpace(text_[pos_])) {
      if (IsBinaryByte(static_cast<unsigned char>(text_[pos_]))) {
        binary_line_ = line_;
        return Token{absl::string_view(), line_};
      }
      ++pos_;
    }
    t.text = text_.substr(start, pos_ - start);
    return t;
  }

  // True when only spaces remain before the end of the current line.
  bool AtLineEnd() {
    SkipSpace(/*stop_at_newline=*/true);
    return pos_ >= text_.size() || text_[pos_] == '\n' || text_[pos_] == '\r';
  }

  // Moves past the end of the current line; returns the rest of the text.
  absl::string_view RestAfterLine() {
    while (pos_ < text_.size() && text_[pos_] != '\n' && text_[pos_] != '\r') ++pos_;
    if (pos_ < text_.size()) Newline();
    return text_.substr(pos_);
  }

  int line() const { return line_; }
  int binary_line() const { return binary_line_; }

 private:
  static bool IsSpace(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
  }

  void Newline() {
    if (text_[pos_] == '\r' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '\n') ++pos_;
    ++pos_;
    ++line_;
  }

  void SkipSpace(bool stop_at_newline) {
    while (pos_ < text_.size() && IsSpace(text_[pos_])) {
      if (text_[pos_] == '\n' || text_[pos_] == '\r') {
        if (stop_at_newline) return;
        Newline();
      } else {
        ++pos_;
      }
    }
  }

  absl::string_view text_;
  size_t pos_ = 0;
  int line_ = 1;
  int binary_line_ = 0;
};

std::optional<double> ParseNumber(absl::string_view s) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty() || !std::isfinite(v)) {
    return std::nullopt;
  }
  return v;
}

std::string Quoted(absl::string_view tok) {
  if (tok.empty()) return "end of file";
  if (tok.size() > 40) return absl::StrCat("'", tok.substr(0, 40), "...'");
  return absl::StrCat("'", tok, "'");
}

class BvhParser {
 public:
  BvhParser(absl::string_view text, absl::string_view source, const BvhLimits& limits)
      : lex_(text), source_(source), limits_(limits) {}

  absl::StatusOr<Motion> Parse() {
    if (absl::Status s = ParseHierarchy(); !s.ok()) return s;
    auto skeleton = Skeleton::Create(std::move(joints_));
    if (!skeleton.ok()) return Error(hierarchy_end_line_, skeleton.status().message());
    Motion motion;
    motion.skeleton = *std::move(skeleton);
    if (absl::Status s = ParseMotion(&motion); !s.ok()) return s;
    return motion;
  }

 private:
  absl::Status Error(int line, absl::string_view what) const {
    return absl::InvalidArgumentError(absl::StrCat(source_, ":", line, ": ", what));
  }

  // Next token, with binary data turned into an error.
  absl::StatusOr<Token> Next() {
    Token t = lex_.Next();
    if (lex_.binary_line() > 0) {
      return Error(lex_.binary_line(), "binary data (control bytes) where BVH text was expected");
    }
    return t;
  }

  absl::Status Expect(absl::string_view keyword, absl::string_view context) {
    absl::StatusOr<Token> t = Next();
    if (!t.ok()) return t.status();
    if (t->text != keyword) {
      return Error(t->line,
                   absl::StrCat("expected '", keyword, "' ", context, ", found ", Quoted(t->text)));
    }
    return absl::OkStatus();
  }

  absl::StatusOr<double> Number(absl::string_view what) {
    absl::StatusOr<Token> t = Next();
    if (!t.ok()) return t.status();
    std::optional<double> v = ParseNumber(t->text);
    if (!v) {
      return Error(t->line, absl::StrCat("expected a finite number for ", what, ", found ",
                                         Quoted(t->text)));
    }
    return *v;
  }

  absl::StatusOr<Vec3> Offset(absl::string_view owner) {
    Vec3 v;
    for (int i = 0; i < 3; ++i) {
      absl::StatusOr<double> x = Number(absl::StrCat("OFFSET of ", owner));
      if (!x.ok()) return x.status();
      v[i] = *x;
    }
    return v;
  }

  // "NAME {" after ROOT or JOINT, then OFFSET and CHANNELS.
  absl::Status ParseJointHeader(int parent) {
    if (static_cast<int>(joints_.size()) >= limits_.max_joints) {
      return Error(lex_.line(), absl::StrCat("more than ", limits_.max_joints, " joints"));
    }
    Joint joint;
    joint.parent = parent;
    const int line = lex_.line();
    std::string name;
    while (!lex_.AtLineEnd()) {  // Names may contain spaces; '{' may share the line.
      absl::StatusOr<Token> t = Next();
      if (!t.ok()) return t.status();
      if (t->text == "{") {
        brace_on_name_line_ = true;
        break;
      }
      absl::StrAppend(&name, name.empty() ? "" : " ", t->text);
    }
    if (name.empty()) return Error(line, "joint has no name");
    if (!names_.insert(name).second)
      return Error(line, absl::StrCat("duplicate joint name '", name, "'"));
    joint.name = name;
    const std::string who = absl::StrCat("joint '", name, "'");
    if (!brace_on_name_line_) {
      if (absl::Status s = Expect("{", "after " + who); !s.ok()) return s;
    }
    brace_on_name_line_ = false;
    if (absl::Status s = Expect("OFFSET", "in " + who); !s.ok()) return s;
    absl::StatusOr<Vec3> offset = Offset(who);
    if (!offset.ok()) return offset.status();
    joint.offset = *offset;
    if (absl::Status s = Expect("CHANNELS", "in " + who); !s.ok()) return s;
    absl::StatusOr<Token> count_tok = Next();
    if (!count_tok.ok()) return count_tok.status();
    std::optional<double> count = ParseNumber(count_tok->text);
    if (!count || *count != std::floor(*count) || *count < 0 || *count > 6) {
      return Error(count_tok->line,
                   absl::StrCat("CHANNELS of ", who, " must be a count from 0 to 6, found ",
                                Quoted(count_tok->text)));
    }
    for (int c = 0; c < static_cast<int>(*count); ++c) {
      absl::StatusOr<Token> t = Next();
      if (!t.ok()) return t.status();
      std::optional<Channel> ch = ParseChannel(t->text);
      if (!ch) {
        if (t->text == "JOINT" || t->text == "End" || t->text == "}" || t->text.empty()) {
          return Error(t->line, absl::StrCat(who, " declares CHANNELS ", *count, " but lists ", c));
        }
        return Error(t->line, absl::StrCat("unknown channel name ", Quoted(t->text), " in ", who,
                                           " (expected Xposition ... Zrotation)"));
      }
      for (Channel seen : joint.channels) {
        if (seen == *ch) {
          return Error(t->line, absl::StrCat(who, " lists channel ", ChannelName(*ch), " twice"));
        }
      }
      joint.channels.push_back(*ch);
    }
    const auto rotations = std::count_if(joint.channels.begin(), joint.channels.end(),
                                         [](Channel c) { return !IsPosition(c); });
    if (rotations != 0 && rotations != 3) {
      return Error(count_tok->line, absl::StrCat(who, " has ", rotations,
                                                 " rotation channels; 0 or 3 are supported"));
    }
    joints_.push_back(std::move(joint));
    open_lines_.push_back(line);
    return absl::OkStatus();
  }

  absl::Status ParseEndSite(int owner) {
    const std::string who = absl::StrCat("End Site of '", joints_[owner].name, "'");
    if (absl::Status s = Expect("Site", "after 'End'"); !s.ok()) return s;
    if (absl::Status s = Expect("{", "after 'End Site'"); !s.ok()) return s;
    if (absl::Status s = Expect("OFFSET", "in " + who); !s.ok()) return s;
    absl::StatusOr<Vec3> offset = Offset(who);
    if (!offset.ok()) return offset.status();
    joints_[owner].end_sites.push_back(*offset);
    return Expect("}", "to close " + who);
  }

  absl::Status ParseHierarchy() {
    absl::StatusOr<Token> t = Next();
    if (!t.ok()) return t.status();
    if (t->text != "HIERARCHY") {
      return Error(t->line, absl::StrCat("expected 'HIERARCHY' at the start of a BVH file, found ",
                                         Quoted(t->text)));
    }
    t = Next();
    if (!t.ok()) return t.status();
    if (t->text != "ROOT") return Error(t->line, "expected 'ROOT', found " + Quoted(t->text));
    if (absl::Status s = ParseJointHeader(-1); !s.ok()) return s;
    std::vector<int> stack = {0};  // Open joints; explicit, so depth costs no C++ stack.
    while (!stack.empty()) {
      t = Next();
      if (!t.ok()) return t.status();
      const Joint& open = joints_[stack.back()];
      if (t->text == "JOINT") {
        if (absl::Status s = ParseJointHeader(stack.back()); !s.ok()) return s;
        stack.push_back(static_cast<int>(joints_.size()) - 1);
      } else if (t->text == "End") {
        if (absl::Status s = ParseEndSite(stack.back()); !s.ok()) return s;
      } else if (t->text == "}") {
        stack.pop_back();
      } else if (ParseChannel(t->text)) {
        return Error(t->line, absl::StrCat("joint '", open.name, "' lists more channel names than",
                                           " its CHANNELS count"));
      } else {
        return Error(t->line,
                     absl::StrCat("expected JOINT, End Site or '}' in joint '", open.name,
                                  "' (opened at line ", open_lines_[stack.back()], "), found ",
                                  Quoted(t->text),
                                  t->text.empty() || t->text == "MOTION" || t->text == "ROOT"
                                      ? ": unbalanced braces"
                                      : ""));
      }
    }
    hierarchy_end_line_ = lex_.line();
    return absl::OkStatus();
  }

  absl::Status ParseMotion(Motion* motion) {
    absl::StatusOr<Token> t = Next();
    if (!t.ok()) return t.status();
    if (t->text == "}") return Error(t->line, "unbalanced braces: '}' with no open joint");
    if (t->text == "ROOT")
      return Error(t->line, "a second ROOT: only one skeleton per file is supported");
    if (t->text != "MOTION") {
      return Error(t->line, "expected 'MOTION' after the hierarchy, found " + Quoted(t->text));
    }
    // "Frames: N" (also "Frames : N").
    t = Next();
    if (!t.ok()) return t.status();
    if (t->text == "Frames") {
      if (absl::Status s = Expect(":", "after 'Frames'"); !s.ok()) return s;
    } else if (t->text != "Frames:") {
      return Error(t->line, "expected 'Frames:', found " + Quoted(t->text));
    }
    t = Next();
    if (!t.ok()) return t.status();
    const int frames_line = t->line;
    std::optional<double> frames = ParseNumber(t->text);
    if (!frames || *frames != std::floor(*frames)) {
      return Error(t->line,
                   "expected a whole frame count after 'Frames:', found " + Quoted(t->text));
    }
    if (*frames <= 0)
      return Error(t->line, absl::StrCat("frame count must be positive, found ", t->text));
    if (*frames > static_cast<double>(limits_.max_frames)) {
      return Error(t->line, absl::StrCat("frame count ", t->text, " is over the limit of ",
                                         limits_.max_frames));
    }
    const int64_t num_frames = static_cast<int64_t>(*frames);
    if (absl::Status s = Expect("Frame", "(Frame Time:)"); !s.ok()) return s;
    if (absl::Status s = Expect("Time:", "after 'Frame'"); !s.ok()) return s;
    absl::StatusOr<double> frame_time = Number("Frame Time");
    if (!frame_time.ok()) return frame_time.status();
    if (*frame_time <= 0) {
      return Error(lex_.line(), absl::StrCat("Frame Time must be positive, found ", *frame_time));
    }
    motion->frame_time = *frame_time;
    const int channels = motion->skeleton.num_channels();
    if (channels == 0) return Error(lex_.line(), "the skeleton has no channels");
    if (!lex_.AtLineEnd()) return Error(lex_.line(), "unexpected text after the Frame Time value");
    int line = lex_.line() + 1;
    const absl::string_view rows = lex_.RestAfterLine();
    return ParseRows(rows, line, num_frames, frames_line, motion);
  }

  absl::Status ParseRows(absl::string_view rows, int line, int64_t num_frames, int frames_line,
                         Motion* motion) {
    const Skeleton& sk = motion->skeleton;
    const int channels = sk.num_channels();
    // Each value takes at least two bytes ("0 "), so the text bounds the rows it can
    // hold; reserving no more than that keeps a lying header from allocating.
    const int64_t most_rows = static_cast<int64_t>(rows.size() / (2 * channels)) + 1;
    motion->values.reserve(static_cast<size_t>(std::min(num_frames, most_rows)) * channels);
    int64_t frame = 0;
    size_t pos = 0;
    for (; pos < rows.size(); ++line) {
      size_t end = pos;
      while (end < rows.size() && rows[end] != '\n' && rows[end] != '\r') ++end;
      const absl::string_view row = rows.substr(pos, end - pos);
      pos = end;
      if (pos < rows.size())
        pos += (rows[pos] == '\r' && pos + 1 < rows.size() && rows[pos + 1] == '\n') ? 2 : 1;
      if (absl::StripAsciiWhitespace(row).empty()) continue;
      if (frame == num_frames) {
        return Error(line, absl::StrCat("more frame rows than 'Frames: ", num_frames, "' (line ",
                                        frames_line, ") declares"));
      }
      if (absl::Status s = ParseRow(row, line, frame, motion); !s.ok()) return s;
      ++frame;
    }
    if (frame < num_frames) {
      return Error(line - 1,
                   absl::StrCat("truncated MOTION section: 'Frames: ", num_frames, "' (line ",
                                frames_line, ") but the file ends after ", frame, " frames"));
    }
    motion->num_frames = static_cast<int>(num_frames);
    return absl::OkStatus();
  }

  absl::Status ParseRow(absl::string_view row, int line, int64_t frame, Motion* motion) {
    const Skeleton& sk = motion->skeleton;
    const int channels = sk.num_channels();
    if (channel_joint_.empty()) {
      for (int j = 0; j < sk.num_joints(); ++j) {
        for (size_t c = 0; c < sk.joint(j).channels.size(); ++c) channel_joint_.push_back(j);
      }
    }
    int count = 0;
    size_t i = 0;
    while (true) {
      while (i < row.size() && (row[i] == ' ' || row[i] == '\t')) ++i;
      if (i >= row.size()) break;
      size_t j = i;
      while (j < row.size() && row[j] != ' ' && row[j] != '\t') ++j;
      const absl::string_view tok = row.substr(i, j - i);
      i = j;
      if (count >= channels) {
        ++count;
        continue;  // Keep counting for the error message.
      }
      std::optional<double> v = ParseNumber(tok);
      if (!v) {
        const int jt = channel_joint_[count];
        const Joint& joint = sk.joint(jt);
        const Channel ch = joint.channels[count - sk.channel_start(jt)];
        for (char c : tok) {
          if (IsBinaryByte(static_cast<unsigned char>(c))) {
            return Error(line, "binary data (control bytes) where BVH text was expected");
          }
        }
        return Error(line, absl::StrCat("frame ", frame, ", value ", count + 1, " (joint '",
                                        joint.name, "' ", ChannelName(ch), "): ", Quoted(tok),
                                        " is not a finite number"));
      }
      motion->values.push_back(*v);
      ++count;
    }
    if (count != channels) {
      return Error(line, absl::StrCat("frame ", frame, " has ", count, " values; the skeleton has ",
                                      channels, " channels"));
    }
    return absl::OkStatus();
  }

  Lexer lex_;
  absl::string_view source_;
  BvhLimits limits_;
  std::vector<Joint> joints_;
  std::vector<int> open_lines_;
  absl::flat_hash_set<std::string> names_;
  std::vector<int> channel_joint_;
  bool brace_on_name_line_ = false;
  int hierarchy_end_line_ = 0;
};

}  // namespace

absl::StatusOr<Motion> ParseBvh(absl::string_view text, absl::string_view source,
                                const BvhLimits& limits) {
  return BvhParser(text, source, limits).Parse();
}

absl::StatusOr<Motion> ReadBvhFile(const std::string& path, const BvhLimits& limits) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open file"));
  const std::streamoff size = in.tellg();
  if (size < 0) return absl::InvalidArgumentError(absl::StrCat(path, ": cannot read file"));
  if (size > limits.max_file_bytes) {
    return absl::InvalidArgumentError(absl::StrCat(
        path, ": file is ", size, " bytes, over the limit of ", limits.max_file_bytes));
  }
  std::string text(static_cast<size_t>(size), '\0');
  in.seekg(0);
  if (!in.read(text.data(), size)) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": read failed"));
  }
  return ParseBvh(text, path, limits);
}

}  // namespace stylus::motion
