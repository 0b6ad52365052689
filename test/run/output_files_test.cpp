// Output files under a full disk (docs/files.md, outputs): a file
// grown past the size limit (RLIMIT_FSIZE, SIGXFSZ ignored as the tools do)
// fails its write; whole files keep their previous version and leave no
// temporary file, the series keeps its complete rows, and each error names
// the file.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "regolith_twin/core/types.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/io/data_file.hpp"

namespace {

std::string dir() { return "/tmp/regolith_output_files_" + std::to_string(::getpid()); }

std::string bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

bool exists(const std::string& path) { return std::ifstream(path).good(); }

// The file size limit for the scope of one check.
class SizeLimit {
 public:
  explicit SizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &old_);
    rlimit r = old_;
    r.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &r);
    handler_ = std::signal(SIGXFSZ, SIG_IGN);
  }
  ~SizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, handler_);
  }

 private:
  rlimit old_{};
  void (*handler_)(int) = SIG_DFL;
};

}  // namespace

TEST(OutputFiles, WholeFileKeepsThePreviousVersionWhenTheDiskIsFull) {
  rt::make_dirs(dir());
  const std::string path = dir() + "/surface.csv";
  rt::write_file(path, "x,y,height\n0,0,1\n");
  EXPECT_FALSE(exists(rt::temp_name(path)));
  {
    SizeLimit limit(1000);
    try {
      rt::write_file(path, "x,y,height\n" + std::string(5000, '1') + "\n");
      FAIL() << "a write past the size limit succeeded";
    } catch (const rt::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path + ": could not write"), std::string::npos) << what;
      EXPECT_NE(what.find("too large"), std::string::npos) << what;
    }
  }
  EXPECT_EQ(bytes(path), "x,y,height\n0,0,1\n");
  EXPECT_FALSE(exists(rt::temp_name(path)));
  rt::JsonObject j;
  j.str("status", "ok");
  j.write(dir() + "/summary.json");
  EXPECT_EQ(bytes(dir() + "/summary.json"), "{\n  \"status\": \"ok\"\n}\n");
  std::remove(path.c_str());
  std::remove((dir() + "/summary.json").c_str());
}

TEST(OutputFiles, SeriesKeepsCompleteRowsWhenTheDiskIsFull) {
  rt::make_dirs(dir());
  const std::string path = dir() + "/series.csv";
  rt::CsvSeries series;
  series.open(path, {"t", "x", "y"});
  std::string error;
  int rows = 0;
  {
    SizeLimit limit(1000);  // not a whole number of rows
    try {
      for (; rows < 1000; ++rows) series.row({rows * 0.001, 1.0 / 3.0, -2.0 / 7.0});
    } catch (const rt::InputError& e) {
      error = e.what();
    }
  }
  EXPECT_NE(error.find(path + ": could not write"), std::string::npos) << error;
  ASSERT_GT(rows, 10);
  ASSERT_LT(rows, 1000);
  const std::string text = bytes(path);
  ASSERT_LE(text.size(), 1000u);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n') << "the row cut off by the limit is not kept";
  EXPECT_EQ(size_t(std::count(text.begin(), text.end(), '\n')), size_t(rows) + 1);  // the header and whole rows
  series.row({1, 2, 3});  // closed after the error: nothing more is written
  EXPECT_EQ(bytes(path), text);
  std::remove(path.c_str());
  ::rmdir(dir().c_str());
}
