// Output files of a run: a CSV time series flushed row by row (so a run that
// stops early leaves a readable file), a small JSON object writer, and whole
// files written to a temporary name and renamed (docs/files.md, outputs).
#pragma once

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace rt {

// Create a folder and its parents (mkdir -p). Throws InputError naming the
// folder if it does not exist afterwards.
void make_dirs(const std::string& dir);

// One run per output folder (docs/files.md, outputs): creates the
// folder, takes an exclusive lock on DIR/.regolith_twin.lock for the
// object's lifetime and removes the summary.json of an earlier run, so a
// folder never holds a finished-looking summary beside a new run's partial
// series. Throws InputError naming the folder when it cannot be written or
// another live process holds it (the lock ends with that process, even when
// it is killed).
class OutputFolder {
 public:
  explicit OutputFolder(const std::string& dir);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

 private:
  int fd_ = -1;
};

// Throws InputError naming `path` unless a file can be created beside it
// (a probe created and removed at once): checks an output path before a
// long run rather than at its end.
void check_writable(const std::string& path);

// Write `text` as write_file_replacing does (regolith_twin/io/data_file.hpp),
// without waiting for the disk: a run killed or stopped by a full disk leaves
// the previous file or none, never part of one.
void write_file(const std::string& path, const std::string& text);

class CsvSeries {
 public:
  CsvSeries() = default;
  CsvSeries(const CsvSeries&) = delete;
  CsvSeries& operator=(const CsvSeries&) = delete;
  ~CsvSeries();
  // Create the file and write the header line. Throws InputError if it cannot.
  void open(const std::string& path, const std::vector<std::string>& columns);
  // One line, flushed. A line that cannot be written whole (a full disk) is
  // cut off again, so the file keeps complete rows only, and InputError
  // names the file and the reason.
  void row(const std::vector<double>& values);
  void close();

 private:
  void put(const std::string& line);
  int fd_ = -1;
  std::string path_;
  long size_ = 0;  // bytes of complete lines
  size_t columns_ = 0;
};

// Flat JSON object: keys in insertion order, numbers, strings, nested objects.
class JsonObject {
 public:
  JsonObject& num(const std::string& key, double v);
  JsonObject& str(const std::string& key, const std::string& v);
  JsonObject& boolean(const std::string& key, bool v);
  JsonObject& obj(const std::string& key, const JsonObject& v);
  JsonObject& nums(const std::string& key, const std::vector<double>& v);
  std::string dump(int indent = 0) const;
  // Write to path atomically (temporary file, then rename).
  void write(const std::string& path) const;

 private:
  std::vector<std::pair<std::string, std::string>> items_;  // key, encoded value
};

}  // namespace rt
