// The sampler's ROS topics (see regolith_twin/ros/scenes/sampler.hpp).
#include "regolith_twin/ros/scenes/sampler.hpp"

#include <cstdio>

#include "regolith_twin/CollectedMass.h"
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

  void markers(const rt::Twin& twin, const std::function<visualization_msgs::Marker(const std::string&, int)>& make,
               visualization_msgs::MarkerArray& out) override {
    const rt::SamplerRun& r = run(twin);
    const rt::HornCount& c = r.segments().now();
    auto mk = make("collected", visualization_msgs::Marker::TEXT_VIEW_FACING);
    const rt::HornGeometry& g = r.scene().geometry;
    const rt::Vec3 p = g.origin + g.axis * (g.top() + 0.1);
    mk.pose.position.x = p.x();
    mk.pose.position.y = p.y();
    mk.pose.position.z = p.z();
    mk.scale.z = 0.04;
    mk.color.r = mk.color.g = mk.color.b = 1.0f;
    char text[256];
    std::snprintf(text, sizeof text, "t = %.2f ms  collected %.1f mg  (%ld/%ld/%ld/%ld/%ld grains in cylinders 1-5)",
                  twin.state().time * 1e3, c.collected_mass() * 1e6, c.count[0], c.count[1], c.count[2], c.count[3],
                  c.count[4]);
    mk.text = text;
    out.markers.push_back(mk);
  }

 private:
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
