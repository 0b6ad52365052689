// Size and nesting limits of the file readers (docs/files.md, "Loaded
// files"): a file above its reader's size limit, and YAML or XML nested
// deeper than 64 levels, are refused with an InputError naming the path and
// the limit before yaml-cpp, urdfdom or a binary reader sees them; the
// shipped files pass.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "regolith_twin/io/checkpoint.hpp"
#include "regolith_twin/io/data_file.hpp"
#include "regolith_twin/io/scenario.hpp"
#include "regolith_twin/io/snapshot.hpp"
#include "regolith_twin/io/urdf_body.hpp"

namespace {

namespace fs = std::filesystem;

// A scratch folder of this test process.
fs::path scratch() {
  static const fs::path d = fs::temp_directory_path() / ("regolith_limits_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

std::string write(const std::string& name, const std::string& text) {
  const fs::path p = scratch() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// A file of `size` bytes that takes no space (a sparse file).
std::string sparse(const std::string& name, std::uintmax_t size) {
  const std::string p = write(name, "");
  fs::resize_file(p, size);
  return p;
}

// The InputError message of f(), or "" when it does not throw one.
std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const rt::InputError& e) {
    return e.what();
  }
  return "";
}

// A valid scene (one grain on a floor) and the same with `extra` top-level text.
std::string scene(const std::string& extra = "") {
  return "name: limits\n"
         "materials:\n  grain: {preset: moderate}\n  wall: {preset: moderate, structure: true}\n"
         "walls:\n  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: wall}\n"
         "grains:\n  - {material: grain, radius: 0.01, position: [0, 0, 0.02]}\n"
         "stages:\n  - {name: fall, duration: 0.01}\n" +
         extra;
}

// `depth` mappings inside one another in block style under key `name`.
std::string block_nest(int depth) {
  std::string s = "name:\n";
  for (int k = 1; k < depth; ++k) s += std::string(2 * k, ' ') + "k:\n";
  return s + std::string(2 * depth, ' ') + "x\n";
}

}  // namespace

TEST(InputLimits, ShippedYamlFilesPassTheNestingScan) {
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator("config")) {
    if (e.path().extension() != ".yaml") continue;
    std::ifstream in(e.path());
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NO_THROW(rt::check_yaml_nesting(e.path().string(), text)) << e.path();
    ++files;
  }
  EXPECT_GT(files, 10);
  EXPECT_NO_THROW(rt::load_scenario(write("ok.yaml", scene())));
}

TEST(InputLimits, YamlNestedDeeperThan64LevelsIsRefused) {
  // Block mappings, flow lists, compact sequences: 64 levels pass the scan, 65 do not.
  EXPECT_NO_THROW(rt::check_yaml_nesting("t", block_nest(63)));
  EXPECT_NE(refusal([] { rt::check_yaml_nesting("t", block_nest(70)); }), "");
  const std::string flow = "seed: " + std::string(70, '[') + std::string(70, ']') + "\n";
  const std::string dashes = "grains:\n" + [] {
    std::string s;
    for (int k = 0; k < 70; ++k) s += "- ";
    return s + "x\n";
  }();
  for (const std::string& deep : {block_nest(70), flow, dashes}) {
    const std::string path = write("deep.yaml", scene(deep));
    const std::string why = refusal([&] { rt::load_scenario(path); });
    EXPECT_NE(why.find(path), std::string::npos) << why;
    EXPECT_NE(why.find("nested deeper than 64 levels"), std::string::npos) << why;
    EXPECT_NE(refusal([&] { rt::parse_scenario_text(scene(deep)); }).find("nested deeper than 64"),
              std::string::npos);
  }
  // A --set value and a base file are scanned too.
  EXPECT_NE(refusal([&] { rt::load_scenario(write("s.yaml", scene()), {"seed=" + std::string(70, '[')}); })
                .find("nested deeper than 64"),
            std::string::npos);
  write("deep_base.yaml", scene(flow));
  EXPECT_NE(refusal([&] { rt::load_scenario(write("child.yaml", "base: deep_base.yaml\n")); })
                .find("nested deeper than 64"),
            std::string::npos);
  // Brackets in quoted text, comments and block scalars are not structure;
  // a quote does not hide brackets that are.
  const std::string text = std::string("name: '") + std::string(70, '[') + "'\n# " + std::string(70, '{') +
                           "\nlabel: |\n  " + std::string(70, '[') + "\n  'x\n";
  EXPECT_NO_THROW(rt::check_yaml_nesting("t", text));
  std::string hidden = "seed: ";
  for (int k = 0; k < 70; ++k) hidden += "[']', ";
  EXPECT_NE(refusal([&] { rt::check_yaml_nesting("t", hidden); }), "");
}

TEST(InputLimits, FilesAboveTheSizeLimitsAreRefused) {
  const auto expect_refused = [](const std::function<void()>& f, const std::string& path, std::size_t limit) {
    const std::string why = refusal(f);
    EXPECT_NE(why.find(path), std::string::npos) << why;
    EXPECT_NE(why.find("limit of " + std::to_string(limit) + " bytes"), std::string::npos) << why;
  };
  // A valid scenario padded with a comment to one byte above 8 MiB.
  std::string big = scene("# ");
  big += std::string(rt::kMaxYamlBytes + 1 - big.size() - 1, 'x') + "\n";
  const std::string yaml = write("big.yaml", big);
  expect_refused([&] { rt::load_scenario(yaml); }, yaml, rt::kMaxYamlBytes);
  const std::string urdf = sparse("big.urdf", rt::kMaxUrdfBytes + 1);
  expect_refused([&] { rt::load_urdf_body(urdf); }, urdf, rt::kMaxUrdfBytes);
  const std::string stl = sparse("big.stl", rt::kMaxMeshBytes + 1);
  expect_refused([&] { rt::load_stl(stl); }, stl, rt::kMaxMeshBytes);
  const std::string bed = sparse("big.bed", rt::kMaxSnapshotBytes + 1);
  expect_refused([&] { rt::read_snapshot(bed); }, bed, rt::kMaxSnapshotBytes);
  const std::string ckpt = sparse("big.ckpt", rt::kMaxCheckpointBytes + 1);
  expect_refused([&] { rt::read_checkpoint_file(ckpt); }, ckpt, rt::kMaxCheckpointBytes);
  const std::string data = sparse("big.data", rt::kMaxGrainDataBytes + 1);
  expect_refused([&] { rt::read_sphere_data(data); }, data, rt::kMaxGrainDataBytes);
  for (const char* f : {"big.yaml", "big.urdf", "big.stl", "big.bed", "big.ckpt", "big.data"}) fs::remove(scratch() / f);
}

TEST(InputLimits, XmlNestedDeeperThan64LevelsIsRefused) {
  const auto urdf = [](int depth) {
    std::string s = "<?xml version=\"1.0\"?>\n<!-- <a><b> -->\n<robot name=\"r\">\n  <link name=\"base\">\n"
                    "    <inertial><mass value=\"1\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" "
                    "iyz=\"0\"/></inertial>\n    <collision><geometry><box size=\"1 1 1\"/></geometry></collision>\n";
    for (int k = 0; k < depth; ++k) s += "<x a=\"<y>\">";
    for (int k = 0; k < depth; ++k) s += "</x>";
    return s + "\n  </link>\n</robot>\n";
  };
  EXPECT_NO_THROW(rt::load_urdf_body(write("flat.urdf", urdf(10))));
  for (const char* f : {"urdf/mascot.urdf", "urdf/sampler_horn.urdf"}) EXPECT_NO_THROW(rt::load_urdf_body(f)) << f;
  const std::string path = write("deep.urdf", urdf(70));
  const std::string why = refusal([&] { rt::load_urdf_body(path); });
  EXPECT_NE(why.find(path), std::string::npos) << why;
  EXPECT_NE(why.find("nested deeper than 64 levels"), std::string::npos) << why;
}

TEST(InputLimits, GrainDataHeaderWithoutACountIsRefusedNotThrownPast) {
  // A title line with the word "atoms" in it is a title; "x atoms" is a
  // malformed count (it used to escape as std::invalid_argument).
  const std::string atoms = "\nAtoms\n\n1 1 0.02 2500 0 0 0.01\n";
  const auto grains = rt::read_sphere_data(write("title.data", "A bed of atoms\n\n1 atoms\n" + atoms));
  EXPECT_EQ(grains.size(), 1u);
  const std::string bad = write("bad.data", "title\n\nx atoms\n" + atoms);
  EXPECT_NE(refusal([&] { rt::read_sphere_data(bad); }).find("malformed header line"), std::string::npos);
  const std::string huge = write("huge.data", "title\n\n99999999999999999999999 atoms\n" + atoms);
  EXPECT_NE(refusal([&] { rt::read_sphere_data(huge); }).find("malformed header line"), std::string::npos);
}
