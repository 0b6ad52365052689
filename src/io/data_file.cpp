// Reader of LAMMPS "atom_style sphere" data files (id type diameter density x y z),
// and the size and nesting limits every file reader applies first.
#include "regolith_twin/io/data_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>

namespace rt {

void check_file_size(const std::string& path, std::size_t max_bytes, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > max_bytes)
    throw InputError(path + ": " + what + " of " + std::to_string(size) + " bytes is larger than the limit of " +
                     std::to_string(max_bytes) + " bytes");
}

std::string temp_name(const std::string& path) { return path + ".tmp." + std::to_string(::getpid()); }

void check_regular_target(const std::string& path, const std::string& what) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);  // through a link: what the name stands for
  if (ec || !std::filesystem::exists(st) || std::filesystem::is_regular_file(st)) return;
  const char* kind = std::filesystem::is_directory(st) ? "a directory"
                     : std::filesystem::is_character_file(st) || std::filesystem::is_block_file(st) ? "a device"
                     : std::filesystem::is_fifo(st) ? "a named pipe"
                     : std::filesystem::is_socket(st) ? "a socket" : "not a regular file";
  throw InputError(path + ": is " + kind + ", not a file: " + what +
                   " is written to a temporary file renamed over its target, which would replace it; give the path "
                   "of a regular file (or of none yet)");
}

void write_file_replacing(const std::string& path, const std::string& bytes, const std::string& what, bool sync) {
  check_regular_target(path, what);
  const std::string tmp = temp_name(path);
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw InputError(path + ": cannot create " + what + " (" + std::strerror(errno) + ")");
  bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size() && std::fflush(f) == 0 &&
            (!sync || ::fsync(fileno(f)) == 0);
  int err = ok ? 0 : errno;
  if (std::fclose(f) != 0 && ok) {
    ok = false;
    err = errno;
  }
  if (ok && std::rename(tmp.c_str(), path.c_str()) != 0) {
    ok = false;
    err = errno;
  }
  if (!ok) {
    std::remove(tmp.c_str());
    throw InputError(path + ": could not write " + what + " (" + std::strerror(err) + ")");
  }
}

std::string path_inside(const std::string& dir, const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InputError(what + ": the path is empty");
  std::error_code ec;
  fs::create_directories(dir, ec);
  const fs::path root = fs::weakly_canonical(dir, ec);
  if (ec) throw InputError(dir + ": the " + what + " directory cannot be used (" + ec.message() + ")");
  const fs::path p = fs::path(path).is_absolute() ? fs::path(path) : fs::path(dir) / path;
  const fs::path real = fs::weakly_canonical(p, ec);  // links followed where the path exists
  if (ec) throw InputError(path + ": cannot resolve the " + what + " path (" + ec.message() + ")");
  const auto [end, _] = std::mismatch(root.begin(), root.end(), real.begin(), real.end());
  if (end != root.end() || real == root)
    throw InputError(path + ": " + what + "s are kept in " + root.string() + " (resolved, this path is " +
                     real.string() + "): give a name inside it, or start the node with another directory");
  return real.string();
}

std::string read_file_bounded(const std::string& path, std::size_t max_bytes, const std::string& what,
                              double timeout) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw InputError(path + ": cannot open " + what + " (" + std::strerror(errno) + ")");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw InputError(path + ": cannot read " + what + " (" + std::strerror(errno) + ")");
  const bool pipe = S_ISFIFO(st.st_mode);
  if (!S_ISREG(st.st_mode) && !pipe)
    throw InputError(path + ": is not a file or a named pipe: a " + what + " is read from a regular file");
  if (!pipe && std::size_t(st.st_size) > max_bytes)
    throw InputError(path + ": " + what + " of " + std::to_string(st.st_size) + " bytes is larger than the limit of " +
                     std::to_string(max_bytes) + " bytes");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  std::string data;
  char chunk[65536];
  for (;;) {
    if (pipe) {
      // Wait for data or the writer's end. Linux reports no hang-up on a
      // pipe that has not had a writer yet, so a pipe nobody opens waits
      // here, in slices, until the deadline.
      const double left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
      if (left <= 0) {
        char b[48];
        std::snprintf(b, sizeof b, "%g", timeout);
        throw InputError(path + ": no " + what + " came through this pipe within " + b + " s: the read is given up");
      }
      struct pollfd q = {fd, POLLIN, 0};
      const int r = ::poll(&q, 1, int(std::min(left, 0.1) * 1000) + 1);
      if (r < 0 && errno != EINTR) throw InputError(path + ": cannot read " + what + " (" + std::strerror(errno) + ")");
      if (r <= 0) continue;
      if (!(q.revents & POLLIN)) break;  // the writer is gone: the end of the data
    }
    const ssize_t got = ::read(fd, chunk, sizeof chunk);
    if (got > 0) {
      data.append(chunk, std::size_t(got));
      if (data.size() > max_bytes)
        throw InputError(path + ": " + what + " is larger than the limit of " + std::to_string(max_bytes) + " bytes");
    } else if (got == 0) {
      break;
    } else if (errno != EINTR && errno != EAGAIN) {
      throw InputError(path + ": cannot read " + what + " (" + std::strerror(errno) + ")");
    }
  }
  return data;
}

std::string read_file_limited(const std::string& path, std::size_t max_bytes, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open " + what);
  check_file_size(path, max_bytes, what);
  // Read in chunks to the end (a pipe or special file has no size to ask for).
  std::string data;
  char chunk[65536];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    data.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (data.size() > max_bytes)
      throw InputError(path + ": " + what + " is larger than the limit of " + std::to_string(max_bytes) + " bytes");
  }
  if (in.bad()) throw InputError(path + ": cannot read " + what);
  return data;
}

void check_yaml_nesting(const std::string& source, const std::string& text, int max_depth) {
  std::vector<std::size_t> indents;  // block levels open at the current line
  int flow = 0;                      // open flow brackets [ {
  char quote = 0;                    // inside a quoted scalar (it may span lines)
  long block_scalar = -1;            // in a | or > scalar: lines indented deeper than this are its text
  long line_no = 0;
  const auto fail = [&]() {
    throw InputError(source + ":" + std::to_string(line_no) + ": YAML nested deeper than " +
                     std::to_string(max_depth) + " levels");
  };
  for (std::size_t pos = 0; pos < text.size();) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    const std::size_t indent = line.find_first_not_of(' ');
    const bool blank = line.find_first_not_of(" \t\r") == std::string::npos;
    if (block_scalar >= 0) {
      if (blank || long(indent) > block_scalar) continue;
      block_scalar = -1;
    }
    if (blank) continue;
    std::size_t i = indent;
    int compact = 0;  // "- - x", "? x", ": x": collections opened on this line
    if (quote == 0 && flow == 0) {
      if (line[indent] == '#') continue;
      while (!indents.empty() && indents.back() > indent) indents.pop_back();
      if (indents.empty() || indents.back() < indent) indents.push_back(indent);
      while (i < line.size() && (line[i] == '-' || line[i] == '?' || line[i] == ':') &&
             (i + 1 == line.size() || line[i + 1] == ' ' || line[i + 1] == '\t')) {
        ++compact;
        i = line.find_first_not_of(" \t", i + 1);
        if (i == std::string::npos) i = line.size();
      }
    }
    if (int(indents.size()) + compact + flow > max_depth) fail();
    std::size_t content_end = line.size();
    for (; i < line.size(); ++i) {
      const char c = line[i];
      const char prev = i > 0 ? line[i - 1] : ' ';
      if (quote == '\'') {
        if (c == '\'' && i + 1 < line.size() && line[i + 1] == '\'') ++i;  // '' inside '...'
        else if (c == '\'') quote = 0;
      } else if (quote == '"') {
        if (c == '\\') ++i;
        else if (c == '"') quote = 0;
      } else if (c == '#' && (prev == ' ' || prev == '\t')) {
        content_end = i;
        break;
      } else if ((c == '\'' || c == '"') && (i == indent || std::string(" \t[{,:").find(prev) != std::string::npos)) {
        quote = c;
      } else if (c == '[' || c == '{') {
        if (int(indents.size()) + compact + ++flow > max_depth) fail();
      } else if ((c == ']' || c == '}') && flow > 0) {
        --flow;
      }
    }
    // A block scalar (| or >, with optional chomping and indentation
    // indicators) ends the line: its text lines are not structure.
    if (quote == 0 && flow == 0) {
      std::size_t e = line.find_last_not_of(" \t\r", content_end == 0 ? 0 : content_end - 1);
      for (int k = 0; k < 2 && e != std::string::npos && e > indent &&
                      (line[e] == '+' || line[e] == '-' || (line[e] >= '1' && line[e] <= '9'));
           ++k)
        --e;
      if (e != std::string::npos && (line[e] == '|' || line[e] == '>') &&
          (e == indent || line[e - 1] == ' ' || line[e - 1] == '\t'))
        block_scalar = long(indent);
    }
  }
}

void check_xml_nesting(const std::string& source, const std::string& text, int max_depth) {
  int depth = 0;
  std::size_t i = text.find('<');
  const auto skip_to = [&](const char* end_mark, std::size_t from) {
    const std::size_t e = text.find(end_mark, from);
    return e == std::string::npos ? text.size() : e + std::strlen(end_mark);
  };
  while (i < text.size()) {
    if (text.compare(i, 4, "<!--") == 0) {
      i = skip_to("-->", i + 4);
    } else if (text.compare(i, 9, "<![CDATA[") == 0) {
      i = skip_to("]]>", i + 9);
    } else if (text.compare(i, 2, "<?") == 0) {
      i = skip_to("?>", i + 2);
    } else {
      // A tag up to its '>' (quoted attribute values may hold '>'); a
      // declaration <!...> may hold an internal subset in [ ].
      const bool closing = i + 1 < text.size() && text[i + 1] == '/';
      const bool declaration = i + 1 < text.size() && text[i + 1] == '!';
      char quote = 0;
      int subset = 0;
      std::size_t j = i + 1;
      for (; j < text.size(); ++j) {
        const char c = text[j];
        if (quote) {
          if (c == quote) quote = 0;
        } else if (c == '"' || c == '\'') {
          quote = c;
        } else if (declaration && c == '[') {
          ++subset;
        } else if (declaration && c == ']' && subset > 0) {
          --subset;
        } else if (c == '>' && subset == 0) {
          break;
        }
      }
      if (j >= text.size()) break;
      if (closing) {
        if (depth > 0) --depth;
      } else if (!declaration && text[j - 1] != '/' && ++depth > max_depth) {
        throw InputError(source + ": XML elements nested deeper than " + std::to_string(max_depth) + " levels");
      }
      i = j + 1;
    }
    i = text.find('<', i);
  }
}

std::vector<GrainRecord> read_sphere_data(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path + ": cannot open grain data file");
  check_file_size(path, kMaxGrainDataBytes, "grain data file");
  // A file is read line by line; anything else (a pipe, a device without
  // line ends) is read whole, up to the limit, first.
  std::error_code ec;
  std::istringstream whole;
  if (!std::filesystem::is_regular_file(path, ec))
    whole.str(read_file_limited(path, kMaxGrainDataBytes, "grain data file"));
  std::istream& in = whole.str().empty() ? static_cast<std::istream&>(file) : whole;
  std::string line;
  long declared = -1;
  int line_no = 0;
  bool in_atoms = false;
  std::vector<GrainRecord> out;
  while (std::getline(in, line)) {
    ++line_no;
    const auto hash = line.find('#');
    const std::string body = line.substr(0, hash);
    std::istringstream ss(body);
    std::string first;
    if (!(ss >> first)) continue;
    if (!in_atoms) {
      std::string second;
      if (ss >> second && second == "atoms" && declared < 0) {
        // "N atoms" (the title line, the first, may hold the word too)
        char* end = nullptr;
        errno = 0;
        declared = std::strtol(first.c_str(), &end, 10);
        if (end == first.c_str() || *end != '\0' || errno == ERANGE || declared < 0)
          throw InputError(path + ":" + std::to_string(line_no) + ": malformed header line (expected: N atoms)");
      } else if (first == "Atoms") {
        in_atoms = true;
      }
      continue;
    }
    if (first.find_first_not_of("0123456789-+.eE") != std::string::npos) break;  // next section
    GrainRecord r{};
    long type = 0;
    double diameter = 0;
    std::istringstream row(body);
    if (!(row >> r.id >> type >> diameter >> r.density >> r.pos.x() >> r.pos.y() >> r.pos.z()) || !(diameter > 0) ||
        !(r.density > 0))
      throw InputError(path + ":" + std::to_string(line_no) +
                       ": malformed atom line (expected: id type diameter>0 density>0 x y z)");
    r.radius = 0.5 * diameter;
    out.push_back(r);
  }
  if (!in_atoms) throw InputError(path + ": no 'Atoms' section found");
  if (declared >= 0 && long(out.size()) != declared)
    throw InputError(path + ": header declares " + std::to_string(declared) + " atoms but " +
                     std::to_string(out.size()) + " were read (truncated file?)");
  return out;
}

}  // namespace rt
