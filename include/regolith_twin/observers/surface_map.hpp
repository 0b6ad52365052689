// Height map of the bed surface: the top of the highest grain per square
// cell over a square of half-width `half` about the z axis, relative to a
// reference height, written as CSV rows "x,y,height" (cells without grains
// left out).
#pragma once

#include <string>

#include "regolith_twin/run/observer.hpp"

namespace rt {

void write_surface(const std::string& path, const Model& m, const State& s, double half, double reference,
                   double cell);

// Writes the map of the final state at the run end.
class SurfaceMap : public Observer {
 public:
  SurfaceMap(std::string path, double half, double reference, double cell)
      : path_(std::move(path)), half_(half), ref_(reference), cell_(cell) {}
  void finish(const Model& m, const State& s) override { write_surface(path_, m, s, half_, ref_, cell_); }

 private:
  std::string path_;
  double half_, ref_, cell_;
};

}  // namespace rt
