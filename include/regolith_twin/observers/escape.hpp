// Grains that leave the scene: a grain whose centre is outside a box is
// taken out of the run (checked every `every` steps) and logged with the
// time, the face it left through, its mass, position and velocity. Far-flung
// ejecta then cost nothing more, and the mass that left through a face (the
// top of a sampler horn) is known. Series columns: escaped_grains,
// escaped_mass (kg).
#pragma once

#include <array>
#include <string>

#include "regolith_twin/run/observer.hpp"

namespace rt {

class Escape : public Observer {
 public:
  enum Face { XMin, XMax, YMin, YMax, ZMin, ZMax };
  struct Exit {
    double t = 0;       // s
    int face = 0;       // Face
    double mass = 0;    // kg
    Vec3 pos = Vec3::Zero(), vel = Vec3::Zero();
  };
  // log_path: CSV of every exit written at the run end ("" none).
  Escape(const Vec3& lo, const Vec3& hi, int every, std::string log_path = "")
      : lo_(lo), hi_(hi), every_(every), log_(std::move(log_path)) {}
  bool leaving(const Model& m, const State& s, std::vector<uint8_t>& drop) override;
  void columns(std::vector<std::string>& out) const override;
  void row(const Model& m, const State& s, std::vector<double>& out) const override;
  void finish(const Model& m, const State& s) override;
  void summary(JsonObject& out) const override;

  const std::vector<Exit>& exits() const { return exits_; }
  double mass() const { return mass_; }                  // kg, all faces
  double mass_through(Face f) const { return face_mass_[f]; }

 private:
  Vec3 lo_, hi_;
  int every_;
  std::string log_;
  std::vector<Exit> exits_;
  double mass_ = 0;
  std::array<double, 6> face_mass_{};
};

}  // namespace rt
