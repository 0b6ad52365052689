// The sampler's ROS topics (see regolith_twin/ros/scenes/sampler.hpp).
#include "regolith_twin/ros/scenes/sampler.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>

#include <geometry_msgs/Point.h>

#include "regolith_twin/CollectedMass.h"
#include "regolith_twin/core/hold.hpp"
#include "regolith_twin/scenes/sampler/sampler_scene.hpp"

namespace rt_ros {
namespace {

class SamplerTopics : public SceneTopics {
 public:
  SamplerTopics(ros::NodeHandle& pnh, const rt::Twin& twin)
      : pub_(pnh.advertise<regolith_twin::CollectedMass>("collected_mass", 10, true)) {}

  void after_step(const rt::Twin& twin, bool clock_due, bool force) override {
    if (clock_due || force) publish(twin);
  }
  void on_end(const rt::Twin& twin) override { publish(twin); }

  // What an operator looks at during a shot (docs/ros.md, "The sampler's view"): the grains inside
  // the horn coloured by cylinder (1 blue ... 5 red), drawn at least kMinDrawn across so that single
  // grains show at the horn's scale, and an overlay beside the horn with the time, the grains in each
  // cylinder and the collected mass against the requirement (green once met).
  void markers(const rt::Twin& twin, const std::function<visualization_msgs::Marker(const std::string&, int)>& make,
               visualization_msgs::MarkerArray& out) override {
    const rt::SamplerRun& r = run(twin);
    const rt::HornCount& c = r.segments().now();
    const rt::HornGeometry& g = r.scene().geometry;
    const rt::Model& m = twin.model();
    const rt::State& s = twin.state();
    static constexpr float kColour[5][3] = {
        {0.25f, 0.55f, 1.0f}, {0.2f, 0.85f, 0.85f}, {0.4f, 0.9f, 0.3f}, {1.0f, 0.8f, 0.2f}, {1.0f, 0.3f, 0.25f}};
    std::array<visualization_msgs::Marker, 5> lists;
    double r_sum = 0;
    long n_in = 0;
    for (int k = 0; k < 5; ++k) {
      lists[k] = make("horn_grains/cylinder_" + std::to_string(k + 1), visualization_msgs::Marker::SPHERE_LIST);
      lists[k].color.r = kColour[k][0];
      lists[k].color.g = kColour[k][1];
      lists[k].color.b = kColour[k][2];
      lists[k].color.a = 1.0f;
    }
    for (int i = 0; i < m.n_grains; ++i) {
      if (rt::held(m, i)) continue;
      const int k = g.segment_of(s.pos[i]);
      if (k < 0) continue;
      geometry_msgs::Point p;
      p.x = s.pos[i].x();
      p.y = s.pos[i].y();
      p.z = s.pos[i].z();
      lists[k].points.push_back(p);
      r_sum += m.grain_radius[i];
      ++n_in;
    }
    const double drawn = std::max(n_in ? 2 * r_sum / double(n_in) : 0.0, kMinDrawn);
    for (auto& mk : lists) {
      mk.scale.x = mk.scale.y = mk.scale.z = drawn;
      // An empty list is taken away (a marker keeps its last points until replaced or deleted).
      if (mk.points.empty()) mk.action = visualization_msgs::Marker::DELETE;
      out.markers.push_back(mk);
    }
    auto mk = make("collected", visualization_msgs::Marker::TEXT_VIEW_FACING);
    const rt::Vec3 side = g.axis.unitOrthogonal();
    const rt::Vec3 p = g.origin + g.axis * (0.5 * (g.segment_z[0] + g.top())) + side * kOverlayOffset;
    mk.pose.position.x = p.x();
    mk.pose.position.y = p.y();
    mk.pose.position.z = p.z();
    mk.scale.z = 0.035;
    const double req = r.scene().spec.requirement, met = r.segments().time_met();
    mk.color.r = met >= 0 ? 0.4f : 1.0f;
    mk.color.g = 1.0f;
    mk.color.b = met >= 0 ? 0.4f : 0.8f;
    mk.color.a = 1.0f;
    char text[320];
    char met_text[64] = "";
    if (met >= 0) std::snprintf(met_text, sizeof met_text, "  (met at %.1f ms)", met * 1e3);
    std::snprintf(text, sizeof text,
                  "t = %.2f ms\ncylinders 1-5: %ld / %ld / %ld / %ld / %ld grains\ncollected %.1f mg of %.0f mg%s",
                  s.time * 1e3, c.count[0], c.count[1], c.count[2], c.count[3], c.count[4], c.collected_mass() * 1e6,
                  req * 1e6, met_text);
    mk.text = text;
    out.markers.push_back(mk);
  }

 private:
  static constexpr double kMinDrawn = 0.008;      // m: the smallest diameter a grain in the horn is drawn at
  static constexpr double kOverlayOffset = 0.35;  // m: the overlay's distance from the horn axis
  static const rt::SamplerRun& run(const rt::Twin& twin) { return static_cast<const rt::SamplerRun&>(twin.run()); }

  void publish(const rt::Twin& twin) {
    const rt::SamplerRun& r = run(twin);
    const rt::HornCount& c = r.segments().now();
    regolith_twin::CollectedMass msg;
    msg.header.stamp = stamp(twin.state().time);
    for (int k = 0; k < 5; ++k) {
      msg.segment_counts.push_back(uint32_t(c.count[k]));
      msg.segment_masses.push_back(c.mass[k]);
    }
    msg.top_grains = uint32_t(c.top_count);
    msg.top_mass = c.top_mass;
    msg.mass = c.collected_mass();
    msg.requirement = r.scene().spec.requirement;
    msg.requirement_met = c.collected_mass() >= msg.requirement;
    msg.time_met = r.segments().time_met();
    pub_.publish(msg);
  }

  ros::Publisher pub_;
};

}  // namespace

std::unique_ptr<SceneTopics> make_sampler_topics(ros::NodeHandle& pnh, const rt::Twin& twin) {
  return std::make_unique<SamplerTopics>(pnh, twin);
}

}  // namespace rt_ros
