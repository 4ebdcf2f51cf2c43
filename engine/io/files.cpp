// Atomic files, directories, JSON and CSV text.
//
// Why temporary-then-rename: rename(2) within one directory replaces the target in one step, so
// any reader sees either the old complete file or the new complete one. The temporary name is a
// hidden file in the same directory (a rename across file systems would not be atomic) and
// carries the pid and a counter so two writers never share one.
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>
#include <fcntl.h>
#include <unistd.h>

#include "asperity/io.hpp"

namespace asperity::io {

namespace fs = std::filesystem;

namespace {
std::atomic<unsigned> temp_counter{0};
}

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  if (target_.filename().empty())
    throw Error("cannot write '" + target_.string() + "': it names a directory, not a file");
  fs::path dir = target_.parent_path();
  if (!dir.empty() && !fs::is_directory(dir))
    throw Error("cannot write '" + target_.string() + "': directory '" + dir.string() +
                "' does not exist (create it first, e.g. asperity.mkdir)");
  temp_ = dir / ("." + target_.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                 std::to_string(temp_counter++));
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);  // best effort: nothing useful to do if it fails
  }
}

void AtomicFile::commit() {
  std::error_code ec;
  fs::rename(temp_, target_, ec);
  if (ec) throw Error("cannot write '" + target_.string() + "': rename failed: " + ec.message());
  committed_ = true;
}

void write_bytes(const fs::path& temp, std::span<const unsigned char> bytes, const std::string& target,
                 bool sync) {
  auto failed = [&](const char* what, int err) {
    return Error("cannot write '" + target + "': " + what + ": " + std::strerror(err));
  };
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw failed("open", errno);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      const int err = w < 0 ? errno : ENOSPC;
      ::close(fd);
      throw failed("write", err);
    }
    done += static_cast<std::size_t>(w);
  }
  if (sync && ::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    throw failed("fsync", err);
  }
  // Some file systems (NFS, or a delayed allocation) report a full disk only here.
  if (::close(fd) != 0) throw failed("close", errno);
}

bool is_complete_png(const fs::path& path) {
  static constexpr unsigned char kEnd[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  unsigned char tail[12] = {};
  const bool ok = std::fseek(f, -12, SEEK_END) == 0 && std::fread(tail, 1, 12, f) == 12 &&
                  std::memcmp(tail, kEnd, 12) == 0;
  std::fclose(f);
  return ok;
}

void write_text_file(const fs::path& path, std::string_view contents) {
  AtomicFile file(path);
  write_bytes(file.temp_path(),
              std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(contents.data()),
                                             contents.size()),
              path.string());
  file.commit();
}

void make_directories(const fs::path& path) {
  std::error_code ec;
  fs::create_directories(path, ec);
  if (ec || !fs::is_directory(path))
    throw Error("cannot create directory '" + path.string() + "'" +
                (ec ? ": " + ec.message() : ": a file of that name exists"));
}

// ---------------------------------------------------------------------------------------------
// JSON

namespace {

void append_json_string(std::string& out, const std::string& s) {
  out += '"';
  for (unsigned char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);  // UTF-8 passes through unchanged
        }
    }
  }
  out += '"';
}

// Shortest text that reads back to the same double ("%.17g" is exact but noisy: 0.1 would
// become 0.10000000000000001).
std::string number_text(double d) {
  char buf[32];
  for (int precision = 15; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, d);
    if (std::strtod(buf, nullptr) == d) break;
  }
  return buf;
}

void append_json(std::string& out, const Json& v, int indent, int depth) {
  auto newline = [&](int d) {
    if (indent <= 0) return;
    out += '\n';
    out.append(static_cast<std::size_t>(indent * d), ' ');
  };
  std::visit(
      [&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::nullptr_t>) {
          out += "null";
        } else if constexpr (std::is_same_v<T, bool>) {
          out += x ? "true" : "false";
        } else if constexpr (std::is_same_v<T, std::int64_t>) {
          out += std::to_string(x);
        } else if constexpr (std::is_same_v<T, double>) {
          out += std::isfinite(x) ? number_text(x) : "null";
        } else if constexpr (std::is_same_v<T, std::string>) {
          append_json_string(out, x);
        } else if constexpr (std::is_same_v<T, Json::Array>) {
          if (x.empty()) { out += "[]"; return; }
          // Arrays of plain numbers stay on one line: a 3-vector over four lines is unreadable.
          bool flat = true;
          for (const Json& e : x)
            if (std::holds_alternative<Json::Array>(e.value) ||
                std::holds_alternative<Json::Object>(e.value))
              flat = false;
          out += '[';
          for (std::size_t i = 0; i < x.size(); ++i) {
            if (i) out += flat ? ", " : ",";
            if (!flat) newline(depth + 1);
            append_json(out, x[i], indent, depth + 1);
          }
          if (!flat) newline(depth);
          out += ']';
        } else {
          if (x.empty()) { out += "{}"; return; }
          out += '{';
          for (std::size_t i = 0; i < x.size(); ++i) {
            if (i) out += ',';
            newline(depth + 1);
            append_json_string(out, x[i].first);
            out += indent > 0 ? ": " : ":";
            append_json(out, x[i].second, indent, depth + 1);
          }
          newline(depth);
          out += '}';
        }
      },
      v.value);
}

}  // namespace

std::string to_json_text(const Json& value, int indent) {
  std::string out;
  append_json(out, value, indent, 0);
  out += '\n';
  return out;
}

void write_json(const fs::path& path, const Json& value) {
  write_text_file(path, to_json_text(value));
}

// ---------------------------------------------------------------------------------------------
// CSV

namespace {
// Quote a header cell only when it needs it (RFC 4180).
std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + '"';
}
}  // namespace

void write_csv(const fs::path& path, std::span<const Column> columns) {
  std::string text;
  std::size_t rows = 0;
  for (std::size_t j = 0; j < columns.size(); ++j) {
    if (j) text += ',';
    text += csv_cell(columns[j].label());
    rows = std::max(rows, columns[j].values.size());
  }
  text += '\n';
  for (std::size_t i = 0; i < rows; ++i) {
    for (std::size_t j = 0; j < columns.size(); ++j) {
      if (j) text += ',';
      if (i < columns[j].values.size()) {
        double v = columns[j].values[i];
        if (std::isnan(v)) text += "nan";
        else if (std::isinf(v)) text += v > 0 ? "inf" : "-inf";
        else text += number_text(v);
      }
    }
    text += '\n';
  }
  write_text_file(path, text);
}

}  // namespace asperity::io
