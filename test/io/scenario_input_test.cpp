// Scenario input and run failures: a malformed or out-of-range value is
// refused with an InputError naming the file, the key (dotted path) and what
// is allowed; a numerical blow-up stops the run with status "blow_up", a
// diagnostic naming step and time, and readable outputs; the command-line
// tool reports both with its documented exit codes.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <array>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "regolith_twin/run/series.hpp"
#include "regolith_twin/run/scenario_kind.hpp"
#include "regolith_twin/io/scenario.hpp"
#include "test_support.hpp"

namespace {

// A valid scene: one grain dropped onto a plane.
const char* const kBase = R"(name: tiny
seed: 3
gravity: [0, 0, -9.81]
materials:
  grain: {preset: moderate}
  wall: {preset: moderate, eps_n: 0.5, eps_t: 1.0, structure: true}
contact: {model: linear, kn: rule, v_max: 1.0, x_max: 0.01, steps_per_contact: 30}
walls:
  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: wall}
grains:
  - name: ball
    material: grain
    radius: 0.005
    position: [0, 0, 0.05]
stages:
  - {name: drop, duration: 0.2}
output:
  every: 0.002
)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t p = text.find(from);
  EXPECT_NE(p, std::string::npos) << "'" << from << "' not in the base scenario";
  if (p != std::string::npos) text.replace(p, from.size(), to);
  return text;
}

class ScenarioInput : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/regolith_scenario_test_XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    if (!HasFailure()) std::system(("rm -rf '" + dir_ + "'").c_str());
  }

  std::string write(const std::string& name, const std::string& text) const {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path) << text;
    return path;
  }

  // Loads `text` from a file called `name` and expects an InputError whose
  // message contains the file path and every string of `parts`.
  void expect_refused(const std::string& name, const std::string& text, const std::vector<std::string>& parts) {
    const std::string path = write(name, text);
    try {
      rt::load_scenario(path);
      ADD_FAILURE() << name << ": accepted";
    } catch (const rt::InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(path), std::string::npos) << name << ": file not named in: " << msg;
      for (const auto& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << name << ": '" << p << "' not in: " << msg;
    } catch (const std::exception& e) {
      ADD_FAILURE() << name << ": wrong exception type: " << e.what();
    }
  }

  std::string dir_;
};

}  // namespace

TEST_F(ScenarioInput, BaseScenarioIsValid) {
  const rt::Scenario sc = rt::load_scenario(write("base.yaml", kBase));
  EXPECT_EQ(sc.model.n_grains, 1);
  EXPECT_EQ(sc.stages.size(), 1u);
  EXPECT_TRUE(sc.warnings.empty());
}

TEST_F(ScenarioInput, NegativeRadiusIsRefused) {
  expect_refused("negative_radius.yaml", replaced(kBase, "radius: 0.005", "radius: -0.005"),
                 {"grains[0].radius", "-0.005", "[1e-07, 10000]"});
}

TEST_F(ScenarioInput, RestitutionAboveOneIsRefused) {
  expect_refused("eps_n.yaml", replaced(kBase, "grain: {preset: moderate}", "grain: {preset: moderate, eps_n: 1.5}"),
                 {"materials.grain.eps_n", "1.5", "[0.001, 1]"});
}

TEST_F(ScenarioInput, UnknownKeyIsRefused) {
  expect_refused("unknown_key.yaml", replaced(kBase, "steps_per_contact: 30}", "steps_per_contact: 30, kn_scale: 2}"),
                 {"contact.kn_scale", "unknown key", "steps_per_contact"});
  expect_refused("unknown_top_key.yaml", std::string(kBase) + "gravity_scale: 2\n",
                 {"gravity_scale", "unknown key", "materials"});
}

TEST_F(ScenarioInput, UnknownMaterialIsRefused) {
  expect_refused("unknown_material.yaml", replaced(kBase, "material: grain", "material: sand"),
                 {"grains[0].material", "'sand'", "grain, wall"});
  expect_refused("unknown_preset.yaml", replaced(kBase, "grain: {preset: moderate}", "grain: {preset: basalt}"),
                 {"materials.grain.preset", "'basalt'", "gravel", "glass_beads"});
}

TEST_F(ScenarioInput, WrongTypeIsRefused) {
  expect_refused("wrong_type.yaml", replaced(kBase, "grain: {preset: moderate}", "grain: {preset: moderate, mu_s: rough}"),
                 {"materials.grain.mu_s", "expected a number", "[0, 100]", "rough"});
  expect_refused("wrong_vector.yaml", replaced(kBase, "gravity: [0, 0, -9.81]", "gravity: [0, -9.81]"),
                 {"gravity", "three numbers"});
  expect_refused("wrong_choice.yaml", replaced(kBase, "type: plane", "type: torus"),
                 {"walls[0].type", "'torus'", "plane", "sphere_shell"});
}

TEST_F(ScenarioInput, PeriodicBoxAndGas) {
  const std::string ok = std::string(kBase) +
                         "periodic: {x: [-0.05, 0.05], y: [0, 0.04]}\n"
                         "gas: {density: 1.27, viscosity: 1.983e-5, sound_speed: 515.6, u0: 2, shear: 100}\n";
  const rt::Scenario sc = rt::load_scenario(write("periodic_gas.yaml", ok));
  EXPECT_TRUE(sc.model.periodic.x && sc.model.periodic.y);
  EXPECT_DOUBLE_EQ(sc.model.periodic.length.x(), 0.1);
  EXPECT_DOUBLE_EQ(sc.model.periodic.lo.y(), 0.0);
  ASSERT_EQ(sc.model.fields.size(), 1u);
  EXPECT_STREQ(sc.model.fields[0]->name(), "gas");
  expect_refused("periodic_short.yaml", std::string(kBase) + "periodic: {x: [0, 0.01]}\n",
                 {"periodic box along x", "at least"});
  expect_refused("periodic_order.yaml", std::string(kBase) + "periodic: {x: [0.1, 0.0]}\n", {"periodic.x[1]"});
  expect_refused("periodic_wall.yaml",
                 replaced(kBase, "normal: [0, 0, 1]", "normal: [1, 0, 0]") + "periodic: {x: [-0.1, 0.1]}\n",
                 {"cuts a periodic direction"});
  expect_refused("gas_missing.yaml", std::string(kBase) + "gas: {density: 1.27}\n", {"gas", "viscosity"});
  expect_refused("gas_vertical.yaml",
                 std::string(kBase) + "gas: {density: 1, viscosity: 1e-5, sound_speed: 300, direction: [0, 0, 1]}\n",
                 {"gas.direction", "horizontal"});
}

TEST_F(ScenarioInput, MissingStagesAreRefused) {
  expect_refused("no_stages.yaml", replaced(kBase, "stages:\n  - {name: drop, duration: 0.2}\n", ""),
                 {"stages", "missing", "duration"});
  expect_refused("zero_duration.yaml", replaced(kBase, "duration: 0.2", "duration: 0"),
                 {"stages[0].duration", "(0, "});
}

TEST_F(ScenarioInput, NonsenseStageValuesAreRefused) {
  // Negative stop criteria (they would never stop a stage, or stop it at once).
  expect_refused("negative_rms.yaml", replaced(kBase, "duration: 0.2}", "duration: 0.2, until_rms_speed: -0.5}"),
                 {"stages[0].until_rms_speed", "-0.5", "out of range"});
  expect_refused("zero_max.yaml", replaced(kBase, "duration: 0.2}", "duration: 0.2, until_max_speed: 0}"),
                 {"stages[0].until_max_speed", "out of range"});
  // A trim plane at or below the floor would remove every grain.
  expect_refused("trim_below.yaml", replaced(kBase, "duration: 0.2}", "duration: 0.2, trim_above: -0.1}"),
                 {"stages[0].trim_above", "not above the floor", "remove every grain"});
  // Above the floor it is accepted.
  EXPECT_NO_THROW(rt::load_scenario(write("trim_ok.yaml", replaced(kBase, "duration: 0.2}", "duration: 0.2, trim_above: 0.04}"))));
}

TEST_F(ScenarioInput, InvalidYamlIsRefused) {
  expect_refused("broken.yaml", replaced(kBase, "radius: 0.005", "radius: [0.005"), {"not valid YAML"});
}

TEST_F(ScenarioInput, UnderResolvedContactIsRefusedUnlessAllowed) {
  const std::string coarse = replaced(kBase, "steps_per_contact: 30}", "dt: 1.0e-3}");
  expect_refused("coarse_dt.yaml", coarse, {"contact.dt", "steps per contact", "guards.allow_under_resolved"});
  const std::string allowed = write("coarse_dt_allowed.yaml", coarse + "guards: {allow_under_resolved: true}\n");
  EXPECT_NO_THROW(rt::load_scenario(allowed));
}

TEST_F(ScenarioInput, DerivedStiffnessStepAndDesignSpeedReplaceTheFilesRules) {
  // A scene kind that derives k_n, dt and the schedule's design speed (the sampler, from its shot speed)
  // hands them to the reader: the model takes them instead of the k_n rule and the dt rule.
  rt::DerivedContact d;
  d.kn = 2.5e6;
  d.dt = 2e-7;
  d.design_speed = 42;
  d.by = "test.speed";
  const std::string base = replaced(kBase, "kn: rule, ", "");  // k_n by the rule, the rule not named
  const std::string with_schedule = base + "schedule: {enabled: false}\n";
  const rt::Scenario plain = rt::parse_scenario_text(with_schedule);
  const rt::Scenario derived = rt::parse_scenario(YAML::Load(with_schedule), "derived.yaml", d);
  EXPECT_NE(plain.model.kn, d.kn);
  EXPECT_EQ(derived.model.kn, d.kn);
  EXPECT_EQ(derived.model.dt, d.dt);
  EXPECT_EQ(plain.model.schedule.speed, 1.0);  // contact.v_max
  EXPECT_EQ(derived.model.schedule.speed, 42.0);
  // the file's own schedule.speed stays
  const rt::Scenario own = rt::parse_scenario(
      YAML::Load(base + "schedule: {enabled: false, speed: 7}\n"), "own.yaml", d);
  EXPECT_EQ(own.model.schedule.speed, 7.0);
  // a derived value the file also gives is refused, naming the key and who derives it
  for (const auto& [from, to, key] : std::vector<std::array<std::string, 3>>{
           {"kn: rule", "kn: 1.0e6", "contact.kn"}, {"steps_per_contact: 30}", "dt: 1.0e-6}", "contact.dt"}}) {
    try {
      rt::parse_scenario(YAML::Load(replaced(base.find(from) != std::string::npos ? base : kBase, from, to)),
                         "both.yaml", d);
      ADD_FAILURE() << key << " accepted twice";
    } catch (const rt::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("test.speed"), std::string::npos) << e.what();
    }
  }
}

namespace {

// --- minimal strict JSON reader (objects, arrays, strings, numbers, literals) ---
struct Json {
  enum Kind { Null, Bool, Number, String, Array, Object } kind = Null;
  bool b = false;
  double num = 0;
  std::string str;
  std::vector<Json> items;
  std::map<std::string, Json> fields;
  const Json& operator[](const std::string& k) const {
    static const Json missing;
    const auto it = fields.find(k);
    return it == fields.end() ? missing : it->second;
  }
};

class JsonReader {
 public:
  explicit JsonReader(const std::string& text) : t_(text) {}
  Json document() {
    Json v = value();
    skip();
    if (p_ != t_.size()) fail("trailing characters");
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error("JSON: " + what + " at offset " + std::to_string(p_));
  }
  void skip() {
    while (p_ < t_.size() && std::isspace(static_cast<unsigned char>(t_[p_]))) ++p_;
  }
  bool eat(char c) {
    skip();
    if (p_ < t_.size() && t_[p_] == c) {
      ++p_;
      return true;
    }
    return false;
  }
  void expect(char c) {
    if (!eat(c)) fail(std::string("expected '") + c + "'");
  }
  std::string string() {
    expect('"');
    std::string s;
    while (p_ < t_.size() && t_[p_] != '"') {
      char c = t_[p_++];
      if (static_cast<unsigned char>(c) < 0x20) fail("control character in string");
      if (c == '\\') {
        if (p_ >= t_.size()) fail("bad escape");
        const char e = t_[p_++];
        switch (e) {
          case '"': case '\\': case '/': s += e; break;
          case 'n': s += '\n'; break;
          case 't': s += '\t'; break;
          case 'r': s += '\r'; break;
          case 'b': s += '\b'; break;
          case 'f': s += '\f'; break;
          case 'u':
            if (p_ + 4 > t_.size()) fail("bad \\u escape");
            s += static_cast<char>(std::stoi(t_.substr(p_, 4), nullptr, 16));
            p_ += 4;
            break;
          default: fail("bad escape");
        }
      } else {
        s += c;
      }
    }
    expect('"');
    return s;
  }
  Json value() {
    skip();
    if (p_ >= t_.size()) fail("unexpected end");
    Json v;
    const char c = t_[p_];
    if (c == '{') {
      v.kind = Json::Object;
      ++p_;
      if (eat('}')) return v;
      do {
        skip();
        const std::string k = string();
        expect(':');
        v.fields[k] = value();
      } while (eat(','));
      expect('}');
    } else if (c == '[') {
      v.kind = Json::Array;
      ++p_;
      if (eat(']')) return v;
      do v.items.push_back(value());
      while (eat(','));
      expect(']');
    } else if (c == '"') {
      v.kind = Json::String;
      v.str = string();
    } else if (t_.compare(p_, 4, "true") == 0 || t_.compare(p_, 5, "false") == 0) {
      v.kind = Json::Bool;
      v.b = t_[p_] == 't';
      p_ += v.b ? 4 : 5;
    } else if (t_.compare(p_, 4, "null") == 0) {
      p_ += 4;
    } else {
      static const std::regex number(R"(-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?)");
      std::smatch mt;
      const std::string rest = t_.substr(p_, 40);
      if (!std::regex_search(rest, mt, number, std::regex_constants::match_continuous)) fail("bad value");
      v.kind = Json::Number;
      v.num = std::stod(mt.str());
      p_ += mt.length();
    }
    return v;
  }
  const std::string& t_;
  size_t p_ = 0;
};

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// series.csv: header and rows of numbers, every row as wide as the header.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  int col(const std::string& name) const {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return int(i);
    return -1;
  }
};

Csv read_csv(const std::string& path) {
  Csv csv;
  std::ifstream f(path);
  std::string line;
  EXPECT_TRUE(std::getline(f, line)) << path << ": empty";
  std::stringstream hs(line);
  for (std::string cell; std::getline(hs, cell, ',');) csv.header.push_back(cell);
  while (std::getline(f, line)) {
    std::vector<double> row;
    std::stringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) {
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      EXPECT_TRUE(!cell.empty() && *end == '\0') << path << ": not a number: '" << cell << "' in " << line;
      row.push_back(v);
    }
    EXPECT_EQ(row.size(), csv.header.size()) << path << ": ragged row: " << line;
    csv.rows.push_back(row);
  }
  return csv;
}

// Step and time named by a blow-up diagnostic ("... at step N (t = T s) ...").
bool parse_blow_up(const std::string& msg, long* step, double* t) {
  static const std::regex re(R"(at step ([0-9]+) \(t = ([-+0-9.eE]+) s\))");
  std::smatch mt;
  if (!std::regex_search(msg, mt, re)) return false;
  *step = std::stol(mt[1]);
  *t = std::stod(mt[2]);
  return true;
}

}  // namespace

namespace {

// The base scene with dt = 1 ms against a contact of ~0.15 ms, in a closed
// gap between two planes: every contact throws the grain back faster.
std::string huge_dt_scene() {
  return replaced(replaced(kBase, "steps_per_contact: 30}", "dt: 1.0e-3}"),
                  "  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: wall}\n",
                  "  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: wall}\n"
                  "  - {type: plane, point: [0, 0, 0.1], normal: [0, 0, -1], material: wall}\n") +
         "guards: {allow_under_resolved: true}\n";
}

// Runs the scenario at `path` and checks the blow-up report and outputs.
void expect_blow_up(const std::string& path, const std::string& out_dir, const std::string& must_mention) {
  rt::Scenario sc = rt::load_scenario(path);
  rt::State s = sc.initial;
  rt::RunOptions opt;
  opt.out_dir = out_dir;
  opt.progress_every = 0;
  const rt::RunReport rep = rt::run_scenario(sc, s, opt);
  ASSERT_EQ(rep.status, "blow_up") << path;
  EXPECT_NE(rep.message.find(must_mention), std::string::npos) << rep.message;
  long step = -1;
  double t = -1;
  ASSERT_TRUE(parse_blow_up(rep.message, &step, &t)) << "no step/time in: " << rep.message;
  EXPECT_GE(step, rep.steps - 1);
  EXPECT_LE(step, rep.steps);
  EXPECT_NEAR(t, step * sc.model.dt, 1e-5 * t + 1e-12);  // printed to 6 digits
  EXPECT_LT(rep.sim_time, sc.stages[0].duration);

  // series.csv: the rows written up to the blow-up, in time order.
  const Csv csv = read_csv(out_dir + "/series.csv");
  ASSERT_GE(csv.col("t"), 0);
  ASSERT_GE(csv.col("E_total"), 0);
  EXPECT_GE(csv.rows.size(), 10u) << "the run should have written rows before blowing up";
  double prev = -1;
  for (const auto& row : csv.rows) {
    const double tr = row[csv.col("t")];
    EXPECT_GT(tr, prev);
    EXPECT_LE(tr, rep.sim_time);
    EXPECT_TRUE(std::isfinite(row[csv.col("E_total")]));
    prev = tr;
  }

  // summary.json: strict JSON with the outcome.
  const std::string text = slurp(out_dir + "/summary.json");
  Json j;
  try {
    j = JsonReader(text).document();
  } catch (const std::exception& e) {
    FAIL() << "summary.json unreadable: " << e.what() << "\n" << text;
  }
  EXPECT_EQ(j["status"].str, "blow_up");
  EXPECT_EQ(j["message"].str, rep.message);
  EXPECT_EQ(j["file"].str, path);
  EXPECT_EQ(j["steps"].num, double(rep.steps));
  EXPECT_EQ(j["energy_initial"].kind, Json::Object);
  EXPECT_TRUE(std::isfinite(j["energy_initial"]["total"].num));
}

}  // namespace

TEST_F(ScenarioInput, HugeTimeStepBlowsUpWithDiagnosticAndReadableOutputs) {
  const std::string path = write("huge_dt.yaml", huge_dt_scene());
  expect_blow_up(path, dir_ + "/huge_dt_out", "blow-up");
}

TEST_F(ScenarioInput, OverlapBeyondGuardBlowsUpWithDiagnosticAndReadableOutputs) {
  // Resolved contact, but an impact at 10 m/s against k_n set for 1 m/s: the
  // overlap reaches ~10 % of the radius, beyond the 5 % guard.
  const std::string text = replaced(replaced(kBase, "position: [0, 0, 0.05]", "position: [0, 0, 0.05]\n    velocity: [0, 0, -10]"),
                                    "output:", "guards: {max_overlap_ratio: 0.05}\noutput:");
  const std::string path = write("overlap.yaml", replaced(text, "every: 0.002", "every: 0.0001"));
  expect_blow_up(path, dir_ + "/overlap_out", "guards.max_overlap_ratio");
}

namespace {

// The regolith_sim binary: $REGOLITH_SIM, else beside this test binary.
std::string sim_path() {
  if (const char* env = std::getenv("REGOLITH_SIM")) return env;
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "regolith_sim";
  std::string self(buf, size_t(n));
  return self.substr(0, self.rfind('/') + 1) + "regolith_sim";
}

// Runs a shell command; returns its exit code and combined output.
int run_command(const std::string& cmd, std::string* output) {
  std::FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return -1;
  char buf[512];
  output->clear();
  while (std::fgets(buf, sizeof buf, p)) *output += buf;
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_F(ScenarioInput, CommandLineToolReportsBadInputWithExitCode2) {
  const std::string sim = sim_path();
  ASSERT_EQ(access(sim.c_str(), X_OK), 0) << sim << " not found: build the regolith_sim target (make all), "
                                          << "or point REGOLITH_SIM at it";
  const std::string bad = write("cli_bad.yaml", replaced(kBase, "grain: {preset: moderate}", "grain: {preset: moderate, eps_n: 1.5}"));
  std::string out;
  EXPECT_EQ(run_command("'" + sim + "' '" + bad + "' --quiet --out '" + dir_ + "/cli_bad_out'", &out), 2) << out;
  EXPECT_NE(out.find("error"), std::string::npos) << out;
  EXPECT_NE(out.find(bad), std::string::npos) << out;
  EXPECT_NE(out.find("materials.grain.eps_n"), std::string::npos) << out;
  EXPECT_NE(out.find("[0.001, 1]"), std::string::npos) << out;

  EXPECT_EQ(run_command("'" + sim + "' '" + dir_ + "/no_such_file.yaml' --quiet", &out), 2) << out;
  EXPECT_NE(out.find("no_such_file.yaml"), std::string::npos) << out;
  EXPECT_EQ(run_command("'" + sim + "' '" + bad + "' --threads zero", &out), 2) << out;
  EXPECT_NE(out.find("--threads"), std::string::npos) << out;
}

TEST_F(ScenarioInput, OneRunPerOutputFolderAndPathsCheckedBeforeTheRun) {
  const std::string sim = sim_path();
  ASSERT_EQ(access(sim.c_str(), X_OK), 0) << sim << " not found";
  // A run long enough to be running while a second one is started into its folder.
  const std::string slow = write("cli_slow.yaml", replaced(kBase, "duration: 0.2", "duration: 1000"));
  const std::string out_dir = dir_ + "/shared_out";
  rt::make_dirs(out_dir);
  std::ofstream(out_dir + "/summary.json") << "{\"status\": \"ok\"}\n";  // an earlier run's summary
  const std::string pid_file = dir_ + "/slow.pid";
  ASSERT_EQ(std::system(("'" + sim + "' '" + slow + "' --quiet --threads 1 --max-steps 1e12 --out '" + out_dir +
                         "' >/dev/null 2>&1 & echo $! > '" + pid_file + "'").c_str()),
            0);
  long pid = 0;
  for (int k = 0; k < 200 && pid == 0; ++k) {
    usleep(20000);
    std::ifstream(pid_file) >> pid;
  }
  ASSERT_GT(pid, 0);
  struct Killer {  // the slow run never outlives the test
    long pid;
    ~Killer() { ::kill(pid_t(pid), SIGKILL); }
  } killer{pid};
  // The folder is taken once the first run has written its lock.
  std::string lock;
  for (int k = 0; k < 500 && lock.find('\n') == std::string::npos; ++k) {
    usleep(20000);
    lock = slurp(out_dir + "/.regolith_twin.lock");
  }
  EXPECT_EQ(lock, std::to_string(pid) + "\n");
  EXPECT_NE(access((out_dir + "/summary.json").c_str(), F_OK), 0) << "the earlier run's summary is still there";
  std::string out;
  EXPECT_EQ(run_command("'" + sim + "' '" + write("cli_quick.yaml", kBase) + "' --quiet --out '" + out_dir + "'", &out), 2)
      << out;
  EXPECT_NE(out.find(out_dir + ": the output folder is in use by another run (pid " + std::to_string(pid) + ")"),
            std::string::npos)
      << out;
  ::kill(pid_t(pid), SIGKILL);  // the lock ends with its process, even killed
  for (int k = 0; k < 200 && ::kill(pid_t(pid), 0) == 0; ++k) usleep(20000);
  const std::string quick = write("cli_quick2.yaml", replaced(kBase, "duration: 0.2", "duration: 0.002"));
  EXPECT_EQ(run_command("'" + sim + "' '" + quick + "' --quiet --threads 1 --out '" + out_dir + "'", &out), 0) << out;
  EXPECT_EQ(access((out_dir + "/summary.json").c_str(), F_OK), 0);
  // Output paths that cannot be written are refused before the run, not after it.
  write("a_file", "x");
  const std::pair<std::string, std::string> bad_paths[] = {
      {"--out '" + dir_ + "/a_file/sub'", dir_ + "/a_file/sub: cannot"},
      {"--out '" + dir_ + "/o2' --checkpoint '" + dir_ + "/no_dir/end.ckpt'", dir_ + "/no_dir/end.ckpt: cannot be written"},
      {"--out '" + dir_ + "/o3' --snapshot '" + dir_ + "/no_dir/end.bed'", dir_ + "/no_dir/end.bed: cannot be written"}};
  for (const auto& [args, expect] : bad_paths) {
    EXPECT_EQ(run_command("'" + sim + "' '" + slow + "' --quiet " + args, &out), 2) << args << ": " << out;
    EXPECT_NE(out.find(expect), std::string::npos) << args << ": " << out;
  }
}

TEST_F(ScenarioInput, ProfileKeysComeBeforeTheCommandLinesOwn) {
  // --profile NAME reads profiles/NAME.yaml beside the scene file; its keys
  // act as --set overrides placed before the command line's own.
  const std::string sim = sim_path();
  ASSERT_EQ(access(sim.c_str(), X_OK), 0) << sim << " not found";
  const std::string scene = write("cli_profile.yaml", replaced(kBase, "duration: 0.2", "duration: 0.002"));
  rt::make_dirs(dir_ + "/profiles");
  write("profiles/fine.yaml", "# a test profile\ncontact.steps_per_contact: 60\n");
  write("profiles/bad.yaml", "contact: {steps_per_contact: 60}\n");
  auto dt_of = [&](const std::string& args, const std::string& out_name) {
    std::string out;
    const std::string out_dir = dir_ + "/" + out_name;
    EXPECT_EQ(run_command("'" + sim + "' '" + scene + "' --quiet --threads 1 --out '" + out_dir + "' " + args, &out), 0)
        << out;
    return JsonReader(slurp(out_dir + "/summary.json")).document()["dt"].num;
  };
  const double dt30 = dt_of("", "p30");
  EXPECT_NEAR(dt_of("--profile fine", "p60") / dt30, 0.5, 1e-9);
  EXPECT_NEAR(dt_of("--profile fine --set contact.steps_per_contact=90", "p90") / dt30, 1.0 / 3.0, 1e-9);
  EXPECT_NEAR(dt_of("--set contact.steps_per_contact=90 --profile fine", "p90b") / dt30, 1.0 / 3.0, 1e-9);
  std::string out;
  EXPECT_EQ(run_command("'" + sim + "' '" + scene + "' --quiet --profile no_such_profile", &out), 2) << out;
  EXPECT_NE(out.find("profiles/no_such_profile.yaml"), std::string::npos) << out;
  EXPECT_EQ(run_command("'" + sim + "' '" + scene + "' --quiet --profile bad", &out), 2) << out;
  EXPECT_NE(out.find("expected a single value"), std::string::npos) << out;
}

TEST_F(ScenarioInput, CommandLineToolReportsBlowUpWithExitCode3) {
  const std::string sim = sim_path();
  ASSERT_EQ(access(sim.c_str(), X_OK), 0) << sim << " not found";
  const std::string path = write("cli_huge_dt.yaml", huge_dt_scene());
  const std::string out_dir = dir_ + "/cli_huge_dt_out";
  std::string out;
  EXPECT_EQ(run_command("'" + sim + "' '" + path + "' --quiet --threads 1 --out '" + out_dir + "'", &out), 3) << out;
  long step = -1;
  double t = -1;
  EXPECT_TRUE(parse_blow_up(out, &step, &t)) << out;
  const std::string summary = slurp(out_dir + "/summary.json");
  EXPECT_NO_THROW(JsonReader(summary).document()) << summary;
  EXPECT_EQ(JsonReader(summary).document()["status"].str, "blow_up");
}

TEST_F(ScenarioInput, CarvedBodyRemovesExactlyTheGrainsItOverlaps) {
  // A lattice of grains and an ellipsoid boulder buried in it: 'carve' removes
  // the grains the ellipsoid overlaps and no others.
  const char* const text = R"(name: carve
materials:
  grain: {preset: moderate}
  rock: {preset: moderate, eps_n: 0.6, eps_t: 0.6, structure: true}
contact: {model: linear, kn: rule, v_max: 0.19, x_max: 0.01, steps_per_contact: 30}
bodies:
  - name: boulder
    shapes: [{type: ellipsoid, size: [0.15, 0.111, 0.0645]}]
    mass: 5.0
    inertia: [0.01648, 0.02666, 0.03482]
    material: rock
    position: [0.01, -0.02, 0.12]
    orientation: {rpy_deg: [0, 0, 30]}
    carve: true
grains:
  - name: bed
    material: grain
    radius: 0.01
    fill: {shape: box, lo: [-0.25, -0.25, 0.0], hi: [0.25, 0.25, 0.3], count: 6000}
stages:
  - {name: rest, duration: 0.01}
)";
  const std::string plain = replaced(text, "    carve: true\n", "");
  const rt::Scenario full = rt::load_scenario(write("plain.yaml", plain));
  const rt::Scenario sc = rt::load_scenario(write("carve.yaml", text));
  ASSERT_GT(full.model.n_grains, 0);
  EXPECT_EQ(full.carved_grains, 0);
  const rt::BodyModel& bm = full.model.bodies[0];
  const rt::BodyState& bs = full.initial.bodies[0];
  int inside = 0;
  for (int i = 0; i < full.model.n_grains; ++i)
    inside += rt::shape_gap(bm, bm.shapes[0], bs.q.conjugate() * (full.initial.pos[i] - bs.pos),
                            full.model.grain_radius[i]).overlap > 0;
  ASSERT_GT(inside, 50) << "the boulder sits inside the lattice";
  EXPECT_EQ(sc.carved_grains, inside);
  EXPECT_EQ(sc.model.n_grains, full.model.n_grains - inside);
  double worst = -1;
  for (int i = 0; i < sc.model.n_grains; ++i)
    worst = std::max(worst, rt::shape_gap(bm, bm.shapes[0], bs.q.conjugate() * (sc.initial.pos[i] - bs.pos),
                                          sc.model.grain_radius[i]).overlap);
  EXPECT_LE(worst, 0.0) << "no grain left inside the boulder";
}

TEST_F(ScenarioInput, BaseFileMergesMappingsAndReplacesLists) {
  write("base.yaml", kBase);
  const std::string derived = write("derived.yaml", R"(base: base.yaml
name: derived
materials:
  grain: {preset: gravel}
stages:
  - {name: longer, duration: 0.5}
)");
  const rt::Scenario sc = rt::load_scenario(derived, {"output.every=0.004"});
  EXPECT_EQ(sc.name, "derived");
  ASSERT_EQ(sc.stages.size(), 1u);
  EXPECT_EQ(sc.stages[0].name, "longer") << "a list replaces the base's";
  EXPECT_DOUBLE_EQ(sc.stages[0].duration, 0.5);
  EXPECT_EQ(sc.model.n_grains, 1) << "grains come from the base";
  EXPECT_DOUBLE_EQ(sc.output_every, 0.004) << "--set applies after the merge";
  rt::Material gravel;
  ASSERT_TRUE(rt::material_preset("gravel", gravel));
  EXPECT_DOUBLE_EQ(sc.model.materials[0].mu_s, gravel.mu_s) << "a mapping merges into the base's";
  EXPECT_DOUBLE_EQ(sc.model.materials[1].eps_n, 0.5) << "untouched base material kept";
  // A missing base and a cycle are refused, naming the file and the key.
  expect_refused("nobase.yaml", "base: absent.yaml\nname: x\n", {"base", "absent.yaml"});
  write("loop_a.yaml", "base: loop_b.yaml\n");
  write("loop_b.yaml", "base: loop_a.yaml\n");
  expect_refused("loop_a.yaml", "base: loop_b.yaml\n", {"base", "cycle"});
}

TEST_F(ScenarioInput, ShippedBoulderAndCliffScenesCarveTheBed) {
  // config/ is read relative to the source tree (the tests' working folder).
  for (const char* file : {"config/mascot_boulder.yaml", "config/mascot_cliff.yaml"}) {
    YAML::Node root = rt::load_document(file);
    ASSERT_TRUE(root["landing"]) << file;
    root.remove("landing");
    const rt::Scenario sc = rt::parse_scenario(root, file);
    ASSERT_EQ(sc.model.bodies.size(), 2u) << file;
    EXPECT_EQ(sc.model.bodies[0].name, "mascot") << file;
    EXPECT_GT(sc.carved_grains, 100) << file;
    EXPECT_EQ(sc.model.n_grains + sc.carved_grains, 63421) << file << ": the shipped moderate bed";
  }
}
