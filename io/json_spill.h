// SpilledJsonArray: a JSON array of one element per frame (run.json's "frames", `nbsim trace info
// --json`'s "frames") kept in a temporary file instead of memory, so that long traces run in
// bounded memory. The document that holds it is written exactly as nlohmann's dump(2) would write
// it with the whole array in place.
#pragma once

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

#include "model/common/error.h"

namespace nbsim::io {

class SpilledJsonArray {
 public:
  // The file lives in the system's temporary folder and is deleted when closed (std::tmpfile).
  SpilledJsonArray() : file_(std::tmpfile()) {
    if (!file_) throw InputError(fmt::format("cannot create a temporary file for per-frame results: {}", std::strerror(errno)));
  }
  ~SpilledJsonArray() { std::fclose(file_); }
  SpilledJsonArray(const SpilledJsonArray&) = delete;
  SpilledJsonArray& operator=(const SpilledJsonArray&) = delete;

  // Appends an element, formatted as dump(2) formats it (its lines are indented when written).
  void push_back(const nlohmann::ordered_json& element) {
    std::string text = element.dump(2);
    put(text);
    ++size_;
  }
  std::uint64_t size() const noexcept { return size_; }

  // The placeholder to put where the array belongs in the document passed to write_document().
  static nlohmann::ordered_json placeholder() { return kPlaceholder; }

  // Writes `document.dump(2)` with the (single) placeholder value replaced by the spilled array,
  // indented as dump(2) indents it at that depth, then a newline.
  void write_document(std::FILE* out, const nlohmann::ordered_json& document) {
    const std::string text = document.dump(2);
    const std::string marker = "\"\\u0001spilled-array\\u0001\"";  // the placeholder, as dump() escapes it
    const std::size_t at = text.find(marker);
    NBSIM_CHECK(at != std::string::npos && text.find(marker, at + 1) == std::string::npos,
                "SpilledJsonArray: the document holds its placeholder not exactly once");
    const std::size_t line = text.rfind('\n', at) + 1;  // the member's line; depth = its leading spaces
    const std::string indent(text.find_first_not_of(' ', line) - line, ' ');
    std::string buf = text.substr(0, at);
    if (size_ == 0) {
      buf += "[]";
    } else {
      buf += "[\n";
      copy_indented(out, buf, indent + "  ");
      buf += '\n' + indent + ']';
    }
    buf.append(text, at + marker.size());
    buf += '\n';
    emit(out, buf);
  }

 private:
  static constexpr const char* kPlaceholder = "\x01spilled-array\x01";

  void put(std::string_view text) {
    // Elements are separated by a NUL, which dump() never writes (it escapes control characters).
    if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() || std::fputc('\0', file_) == EOF)
      throw InputError(fmt::format("cannot write per-frame results to a temporary file: {}", std::strerror(errno)));
  }

  static void emit(std::FILE* out, std::string& buf) {
    if (std::fwrite(buf.data(), 1, buf.size(), out) != buf.size())
      throw InputError(fmt::format("cannot write the per-frame results: {}", std::strerror(errno)));
    buf.clear();
  }

  // Copies the elements back to `out` through `buf` (flushed every 64 KiB), each line indented,
  // elements separated by ",\n".
  void copy_indented(std::FILE* out, std::string& buf, const std::string& indent) {
    if (std::fflush(file_) != 0 || std::fseek(file_, 0, SEEK_SET) != 0)
      throw InputError(fmt::format("cannot read back per-frame results from a temporary file: {}", std::strerror(errno)));
    char chunk[1 << 16];
    bool line_start = true;
    std::size_t n = 0;
    while ((n = std::fread(chunk, 1, sizeof chunk, file_)) > 0) {
      for (std::size_t i = 0; i < n; ++i) {
        const char c = chunk[i];
        if (c == '\0') {  // an element's end: a separator, except after the last
          if (++copied_ < size_) buf += ",\n";
          line_start = true;
          continue;
        }
        if (line_start) buf += indent;
        line_start = false;
        buf += c;
        if (c == '\n') line_start = true;
        if (buf.size() >= sizeof chunk) emit(out, buf);
      }
    }
    if (std::ferror(file_) || copied_ != size_)
      throw InputError("cannot read back per-frame results from a temporary file");
    std::fseek(file_, 0, SEEK_END);
    copied_ = 0;
  }

  std::FILE* file_ = nullptr;
  std::uint64_t size_ = 0, copied_ = 0;
};

}  // namespace nbsim::io
