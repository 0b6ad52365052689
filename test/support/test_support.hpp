// Helpers shared by the engine tests: small models built in code.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "regolith_twin/core/body.hpp"
#include "regolith_twin/core/energy.hpp"
#include "regolith_twin/core/model.hpp"
#include "regolith_twin/core/state.hpp"
#include "regolith_twin/core/step.hpp"
#include "regolith_twin/run/run.hpp"
#include "regolith_twin/run/scene.hpp"

namespace rt::test {

// A figure for the test report (gtest XML property), 4 significant digits.
std::string figure(double v);

// A material with the given restitution and friction (no rolling/twisting).
Material simple_material(const std::string& name, double density, double eps_n, double eps_t, double mu_s);

// Free grains of the given radii in a row along x at z = 1 mm, `spacing`
// apart (centres), of one material `grain` (2700 kg/m^3, ε 0.8, μ 0.2), no
// gravity, k_n = 8000 N/m, Δt = 1 µs: a model (finalized) and its state.
void grains_in_a_row(Model& m, State& s, const std::vector<double>& radii, double spacing);

// Materials `grain` (0) and `wall` (1, a structure), both density 2430,
// ε_n = ε_t = μ = 0.5, and an open box: a floor at z = 0 and side planes at
// x, y = 0 and side.
void grain_and_wall_in_open_box(Model& m, double side);

// A published preset (grains, material 0) and the same material as a
// structure named `wall` (material 1); false if the preset is unknown.
bool preset_with_wall(Model& m, const std::string& preset);

// A body of one box shape of half extents `half` centred on its centre of
// mass, of the given density (mass and principal inertia from them).
BodyModel box_body(const std::string& name, const Vec3& half, double density, bool fixed, int material);

// The closed box [lo, hi] as a triangle mesh, each face cut into n x n
// cells of two triangles, wound outwards (vertices shared within a face).
TriangleMesh box_mesh(const Vec3& lo, const Vec3& hi, int n);

// A prepared scene run to its end from (m, s), normally copies of sc.sc.model
// and sc.start that the run advances, with the scene's observers and no
// progress lines: the run's report and the scene's run (its results).
struct SceneRunOutcome {
  RunReport report;
  std::unique_ptr<SceneRun> run;
};
SceneRunOutcome run_scene(const Scene& sc, Model& m, State& s);

}  // namespace rt::test
