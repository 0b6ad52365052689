// Plain grain files: the LAMMPS "atom_style sphere" data format (id type
// diameter density x y z), read by the peers of the benchmark as well, and a
// simple text dump of the final state.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "regolith_twin/core/types.hpp"

namespace rt {

struct GrainRecord {
  long id;
  double radius;   // m
  double density;  // kg/m^3
  Vec3 pos;        // m
};

// Read the Atoms section of a LAMMPS sphere data file. Throws InputError
// naming the file and line on malformed content.
std::vector<GrainRecord> read_sphere_data(const std::string& path);

// Limits on what a reader accepts before a parser (yaml-cpp, urdfdom, the STL,
// snapshot and checkpoint readers, Bullet through the meshes) sees a file
// (docs/files.md, "Loaded files"). Generous against the shipped files:
// scenario YAML and URDF files are a few kB, STL meshes 50 kB, bed snapshots
// 3 MB, checkpoints of the shipped beds ~100 MB.
constexpr std::size_t kMaxYamlBytes = std::size_t(8) << 20;         // scenarios, profiles, --set values
constexpr std::size_t kMaxUrdfBytes = std::size_t(8) << 20;         // URDF files
constexpr std::size_t kMaxMeshBytes = std::size_t(256) << 20;       // STL meshes (5 M binary facets)
constexpr std::size_t kMaxSnapshotBytes = std::size_t(2) << 30;     // bed snapshots (67 M float64 grains)
constexpr std::size_t kMaxCheckpointBytes = std::size_t(16) << 30;  // checkpoints (~20 M grains)
constexpr std::size_t kMaxGrainDataBytes = std::size_t(4) << 30;    // LAMMPS grain data files
constexpr int kMaxNesting = 64;  // YAML collections or XML elements inside one another

// Throws InputError naming the path, `what` it is and the limit when the
// file is larger than max_bytes. A file whose size cannot be asked (a pipe) passes.
void check_file_size(const std::string& path, std::size_t max_bytes, const std::string& what);

// The whole file, refused as check_file_size does (also when a pipe delivers
// more than max_bytes). Throws InputError "<path>: cannot open <what>" when
// it cannot be opened.
std::string read_file_limited(const std::string& path, std::size_t max_bytes, const std::string& what);

// `path` (relative: taken from `dir`) when it lies inside `dir` once every
// link is followed, else an InputError naming both and what to do (a path
// outside, or a link out of the directory). `dir` is created if missing.
// Used for the node's checkpoints (~checkpoint_dir; docs/ros.md).
std::string path_inside(const std::string& dir, const std::string& path, const std::string& what);

// read_file_limited for a file that may be a named pipe: a regular file is
// read whole; a pipe is read until its writer closes it or `timeout` seconds
// pass (an InputError then), so a pipe nobody writes cannot hold the reader
// for ever; any other kind of file (a device, a directory) is refused.
std::string read_file_bounded(const std::string& path, std::size_t max_bytes, const std::string& what,
                              double timeout);

// A temporary name beside `path`, unique to this process (written, then
// renamed over `path`).
std::string temp_name(const std::string& path);

// A target that exists and is not a regular file (a device such as
// /dev/full, a pipe, a directory) is refused with an InputError naming it:
// the rename would replace it. Called by write_file_replacing and check_writable.
void check_regular_target(const std::string& path, const std::string& what);

// Write `bytes` to temp_name(path) (flushed to the disk first when `sync`),
// then rename it over `path`: a writer killed or stopped by a full disk
// leaves the previous file or none, never part of one. Throws InputError
// "<path>: cannot create <what> (reason)" or "<path>: could not write <what>
// (reason)", the temporary file removed.
void write_file_replacing(const std::string& path, const std::string& bytes, const std::string& what, bool sync);

// Refuse YAML text whose collections nest deeper than max_depth: a pre-scan
// of block indentation, sequence dashes and flow brackets (quoted text,
// comments and block scalars skipped). `source` names the text in the error.
void check_yaml_nesting(const std::string& source, const std::string& text, int max_depth = kMaxNesting);

// Refuse XML text whose elements nest deeper than max_depth.
void check_xml_nesting(const std::string& source, const std::string& text, int max_depth = kMaxNesting);

}  // namespace rt
