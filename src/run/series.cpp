// CSV series and JSON summary writers.
#include "regolith_twin/run/series.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "regolith_twin/core/types.hpp"
#include "regolith_twin/io/data_file.hpp"

namespace rt {
namespace {

std::string encode_num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string encode_str(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\t': o += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char b[8];
          std::snprintf(b, sizeof b, "\\u%04x", c);
          o += b;
        } else {
          o += c;
        }
    }
  }
  return o + "\"";
}

}  // namespace

void make_dirs(const std::string& dir) {
  std::string partial;
  for (size_t i = 0; i <= dir.size(); ++i) {
    if ((i == dir.size() || dir[i] == '/') && !partial.empty()) ::mkdir(partial.c_str(), 0755);
    if (i < dir.size()) partial += dir[i];
  }
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) throw InputError(dir + ": cannot create the folder");
}

void write_file(const std::string& path, const std::string& text) {
  write_file_replacing(path, text, "output file", /*sync=*/false);
}

OutputFolder::OutputFolder(const std::string& dir) {
  make_dirs(dir);
  const std::string lock = dir + "/.regolith_twin.lock";
  fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(dir + ": cannot write in the output folder (" + std::strerror(errno) + ")");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    char buf[32] = {0};
    const ssize_t n = ::pread(fd_, buf, sizeof buf - 1, 0);
    ::close(fd_);
    fd_ = -1;
    const std::string pid = n > 0 ? std::string(buf, size_t(n)) : std::string("?");
    throw InputError(dir + ": the output folder is in use by another run (pid " + pid.substr(0, pid.find('\n')) +
                     "); give another output folder or wait until that run ends");
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) != ssize_t(pid.size())) {
    ::close(fd_);
    fd_ = -1;
    throw InputError(dir + ": cannot write in the output folder (" + std::strerror(errno) + ")");
  }
  // The summary of an earlier run would look finished beside this run's partial outputs.
  const std::string summary = dir + "/summary.json";
  if (std::remove(summary.c_str()) != 0 && errno != ENOENT)
    throw InputError(summary + ": cannot remove the summary of an earlier run (" + std::strerror(errno) + ")");
}

OutputFolder::~OutputFolder() {
  if (fd_ >= 0) ::close(fd_);
}

void check_writable(const std::string& path) {
  check_regular_target(path, "this output");
  // Named like every temporary file (name.tmp.PID), so that one left by a kill is recognised as such.
  const std::string probe = temp_name(path + ".probe");
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(path + ": cannot be written (" + std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(probe.c_str());
}

CsvSeries::~CsvSeries() { close(); }

void CsvSeries::open(const std::string& path, const std::vector<std::string>& columns) {
  close();
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(path + ": cannot create output file (" + std::strerror(errno) + ")");
  path_ = path;
  size_ = 0;
  columns_ = columns.size();
  std::string line;
  for (size_t i = 0; i < columns.size(); ++i) line += (i ? "," : "") + columns[i];
  put(line + "\n");
}

void CsvSeries::row(const std::vector<double>& values) {
  if (fd_ < 0) return;
  std::string line;
  char buf[32];
  for (size_t i = 0; i < values.size() && i < columns_; ++i) {
    std::snprintf(buf, sizeof buf, "%s%.10g", i ? "," : "", values[i]);
    line += buf;
  }
  put(line + "\n");
}

// One write per line (no buffer left to flush later), so a killed run
// leaves complete lines.
void CsvSeries::put(const std::string& line) {
  size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n > 0) {
      done += size_t(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    const int err = n < 0 ? errno : EIO;
    // Keep the complete lines: a part of this one may have reached the file.
    const bool cut = ::ftruncate(fd_, size_) == 0;
    close();
    throw InputError(path_ + ": could not write output file (" + std::strerror(err) + ")" +
                     (cut ? "; it keeps the rows written before" : ""));
  }
  size_ += long(line.size());
}

void CsvSeries::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

JsonObject& JsonObject::num(const std::string& k, double v) {
  items_.emplace_back(k, encode_num(v));
  return *this;
}
JsonObject& JsonObject::str(const std::string& k, const std::string& v) {
  items_.emplace_back(k, encode_str(v));
  return *this;
}
JsonObject& JsonObject::boolean(const std::string& k, bool v) {
  items_.emplace_back(k, v ? "true" : "false");
  return *this;
}
JsonObject& JsonObject::obj(const std::string& k, const JsonObject& v) {
  items_.emplace_back(k, "\x01" + v.dump(0));  // marker: nested, re-indented on dump
  return *this;
}
JsonObject& JsonObject::nums(const std::string& k, const std::vector<double>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + encode_num(v[i]);
  items_.emplace_back(k, s + "]");
  return *this;
}

std::string JsonObject::dump(int indent) const {
  const std::string pad(indent + 2, ' '), end_pad(indent, ' ');
  std::ostringstream os;
  os << "{\n";
  for (size_t i = 0; i < items_.size(); ++i) {
    std::string v = items_[i].second;
    if (!v.empty() && v[0] == '\x01') {
      // Nested object: re-indent its lines.
      std::string inner = v.substr(1), out;
      for (char c : inner) {
        out += c;
        if (c == '\n') out += std::string(indent + 2, ' ');
      }
      v = out;
    }
    os << pad << encode_str(items_[i].first) << ": " << v << (i + 1 < items_.size() ? "," : "") << "\n";
  }
  os << end_pad << "}";
  return os.str();
}

void JsonObject::write(const std::string& path) const { write_file(path, dump(0) + "\n"); }

}  // namespace rt
