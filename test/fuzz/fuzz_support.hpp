// Shared by the fuzz targets (test/fuzz/*_fuzz.cpp, docs/validation/reliability.md,
// "Fuzzing"): a scratch folder per process in which an input's parts are
// written as files, the readers being file readers, and the split of one
// input into parts.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#ifndef REGOLITH_FUZZ_ROOT
#define REGOLITH_FUZZ_ROOT "."
#endif

namespace rt::fuzz {

namespace fs = std::filesystem;

// The repository (urdf/ and the small files under test/fuzz/).
inline fs::path repo_root() { return fs::path(REGOLITH_FUZZ_ROOT); }

// A scratch folder of this process, removed at exit. It holds config/ (the
// documents of an input, with config/beds/small.bed, a small shipped-format
// snapshot) and urdf/ (a link to the repository's URDFs and meshes), so a
// scenario's relative references resolve as in the repository.
inline const fs::path& scratch() {
  static const fs::path dir = [] {
    std::string tmpl = (fs::temp_directory_path() / "regolith_fuzz.XXXXXX").string();
    if (!::mkdtemp(tmpl.data())) std::abort();
    const fs::path d(tmpl);
    fs::create_directories(d / "config" / "beds");
    std::error_code ec;
    fs::create_directory_symlink(fs::absolute(repo_root() / "urdf"), d / "urdf", ec);
    fs::copy_file(repo_root() / "test" / "fuzz" / "small.bed", d / "config" / "beds" / "small.bed", ec);
    static const std::string keep = d.string();
    std::atexit([] {
      std::error_code e;
      fs::remove_all(keep, e);  // does not follow the urdf link
    });
    return d;
  }();
  return dir;
}

inline std::string write(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  return path.string();
}

// The parts of `data` between occurrences of `marker`.
inline std::vector<std::string> split(const std::string& data, const std::string& marker) {
  std::vector<std::string> parts;
  std::size_t from = 0;
  for (std::size_t at; (at = data.find(marker, from)) != std::string::npos; from = at + marker.size())
    parts.push_back(data.substr(from, at - from));
  parts.push_back(data.substr(from));
  return parts;
}

// A scenario input: the main document, then optionally a line "#@base" and
// the document it names as `base: base.yaml`; lines "#@set KEY=VALUE"
// (YAML comments) anywhere are --set overrides. Returns the main file's path.
inline std::string write_documents(const std::string& data, std::vector<std::string>& overrides) {
  const std::vector<std::string> parts = split(data, "\n#@base\n");
  std::size_t from = 0;
  for (std::size_t at; (at = data.find("#@set ", from)) != std::string::npos; from = at + 6) {
    const std::size_t eol = data.find('\n', at);
    overrides.push_back(data.substr(at + 6, eol == std::string::npos ? std::string::npos : eol - at - 6));
  }
  const fs::path dir = scratch() / "config";
  write(dir / "base.yaml", parts.size() > 1 ? parts[1] : std::string());
  return write(dir / "main.yaml", parts[0]);
}

}  // namespace rt::fuzz
