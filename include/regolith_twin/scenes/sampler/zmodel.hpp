// Maxwell's Z-model of crater excavation flow, and a fit of Z (and of the
// height of the flow centre) to a measured field of grain velocities
// (sampler scene). Pure functions; nothing here knows a model or a state.
//
// Frame. z is vertical, up; the impact point is on the surface (the plane
// z = impact.z). For a point p, x is the horizontal distance from the
// vertical axis through the impact point, depth = impact.z - p.z (positive
// below the surface), and the radial unit vector is the horizontal unit
// vector from the axis to p.
//
// Polar coordinates (r, θ) are centred on the flow centre, which is on the
// axis at height H₀ above the surface (H₀ = 0: the impact point itself);
// θ = 0 is straight down:
//     θ = atan2(x, H₀ - z) = atan2(x, H₀ + depth),   r = |p - centre|.
// atan2 gives θ in [0, π]: a point above a centre that lies below the
// surface (H₀ < 0, depth < -H₀) has θ > π/2.
//
// Streamline of the Z-model through the surface at distance R:
//     r = R (1 - cos θ)^{1/(Z-2)}.
// Velocity: u_r = α/r^Z, u_θ = u_r (Z-2) sin θ / (1 + cos θ) (u_θ > 0: the
// flow turns from downward to outward and upward). In (radial, vertical-up)
// components, up to the positive factor u_r / (1 + cos θ):
//     v_x = sin θ (1 + (Z-1) cos θ)
//     v_z = (1 + cos θ) ((Z-2) - (Z-1) cos θ)
// Velocity angle: θ_v = atan2(v_z, v_x), the angle of the velocity to the
// horizontal measured from the horizontal pointing away from the axis,
// positive upward, in (-π, π]. For 0 < θ < π this is the same angle as
//     atan{[(Z-2) sin θ - (Z-1) sin θ cos θ] / [1 + (Z-2) cos θ - (Z-1) cos² θ]}
// (the two fractions differ by the positive factor sin θ / (1 + cos θ));
// the form with components has no 0/0 at θ = 0 (straight down, -π/2) and
// keeps the branch right for θ > π/2. At θ = π/2, θ_v = atan(Z - 2), the
// ejection angle.
//
// Measured field. Grains whose speed is above speed_min (given by the
// caller, e.g. 10 times the bed's rest RMS speed) and that lie in the region
// x_min <= x < x_max, depth_min <= depth < depth_max are binned in
// axisymmetric toroidal cells of section cell × cell (x × depth), cell
// (i, j) covering x_min + i·cell <= x < x_min + (i+1)·cell and the same in
// depth from depth_min (a last cell cut by the region's edge keeps the part
// inside; its centre is the centre of that part). Each grain's velocity is
// made a unit vector and projected on its (radial, vertical) plane (the
// azimuthal part is dropped, so a grain moving mostly around the axis
// counts little); a cell's measured angle is the angle to the horizontal
// of the mean of these projected directions (same convention as θ_v).
// surface_only keeps the top layer of cells only (depth_min to
// depth_min + cell).
//
// Fit. Each cell with at least min_grains grains has the model angle
// θ_v(Z, θ of the cell centre). Z (and, with fit_h0, H₀) minimises the RMS
// over cells of (measured - model), wrapped to (-π, π]. Z: a scan of
// z_steps points over [z_min, z_max], then golden-section search between
// the neighbours of the best point; H₀: the same over [h0_min, h0_max],
// each H₀ with its own best Z (nested). Deterministic (no random start, sums
// in cell order). The report has the mean and the population SD of
// (measured - model) over the cells at the optimum (RMS² = mean² + SD²).
#pragma once

#include <vector>

#include "regolith_twin/core/types.hpp"

namespace rt {

// Velocity angle to the horizontal (rad; positive up, from the horizontal
// pointing away from the axis) of the Z-model flow at polar angle theta
// (rad, 0 = straight down). Z > 2.
double zmodel_velocity_angle(double Z, double theta);

// Polar angle θ (rad) of a point at horizontal distance x from the axis and
// depth below the surface, for a flow centre H₀ above the surface.
double zmodel_polar_angle(double x, double depth, double h0 = 0);

// Streamline radius r = R (1 - cos θ)^{1/(Z-2)} (distance from the flow
// centre) of the streamline that meets the surface plane of the centre at R.
double zmodel_streamline_radius(double Z, double R, double theta);

// Unit vector of the model velocity at point p (3-D, world frame) for the
// impact point `impact` and a flow centre h0 above it. On the axis: straight
// down.
Vec3 zmodel_direction(double Z, const Vec3& p, const Vec3& impact, double h0 = 0);

struct ZFitOptions {
  Vec3 impact = Vec3::Zero();  // impact point on the surface (m)
  double cell = 2.5e-3;        // cell section side (m)
  double x_min = 0.04;         // region: horizontal distance from the axis (m)
  double x_max = 0.10;
  double depth_min = 0;        // region: depth below the surface (m)
  double depth_max = 0.065;
  bool surface_only = false;   // only the top layer of cells (depth_min .. depth_min + cell)
  double speed_min = 0;        // grains at or below this speed are left out (m/s)
  int min_grains = 1;          // a cell needs at least this many grains
  double z_min = 2.01;         // search range of Z
  double z_max = 6;
  bool fit_h0 = false;         // fit the height of the flow centre too
  double h0 = 0;               // flow centre height above the surface when not fitted (m)
  double h0_min = -0.05;       // search range of H₀ when fitted (m)
  double h0_max = 0.05;
  int z_steps = 100;           // scan points before the golden-section search
  int h0_steps = 41;
  double z_tol = 1e-6;         // golden-section stopping width
  double h0_tol = 1e-7;        // (m)
};

// One cell of the measured field.
struct ZCell {
  double x = 0;      // centre: horizontal distance from the axis (m)
  double depth = 0;  // centre: depth below the surface (m)
  double angle = 0;  // angle of the mean direction to the horizontal (rad)
  int grains = 0;
};

struct ZFit {
  double z = 0;                // NaN when no cell was usable
  double h0 = 0;               // fitted H₀ (m), or options.h0 when not fitted
  double misfit_mean_deg = 0;  // mean of (measured - model) over cells, deg
  double misfit_sd_deg = 0;    // population SD of (measured - model), deg
  double misfit_rms_deg = 0;   // the minimised RMS, deg
  int cells = 0;               // cells used
  int grains = 0;              // grains in those cells
};

// The measured cells (those with at least min_grains grains), in order of
// depth layer then x. Throws InputError on an invalid region or option, or
// if pos and vel differ in size.
std::vector<ZCell> zmodel_cells(const std::vector<Vec3>& pos, const std::vector<Vec3>& vel,
                                const ZFitOptions& opt);

// RMS (rad) of measured - model over the cells for Z and H₀.
double zmodel_rms(const std::vector<ZCell>& cells, double Z, double h0);

// Fit of Z (and H₀ with fit_h0) to cells, or to grains' positions and velocities.
ZFit fit_zmodel(const std::vector<ZCell>& cells, const ZFitOptions& opt);
ZFit fit_zmodel(const std::vector<Vec3>& pos, const std::vector<Vec3>& vel, const ZFitOptions& opt);

}  // namespace rt
