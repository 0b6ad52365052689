// The landing's ROS topics (see regolith_twin/ros/scenes/landing.hpp).
#include "regolith_twin/ros/scenes/landing.hpp"

#include <cstdio>

#include "regolith_twin/LandingOutcome.h"
#include "regolith_twin/scenes/landing/landing_scene.hpp"

namespace rt_ros {
namespace {

class LandingTopics : public SceneTopics {
 public:
  LandingTopics(ros::NodeHandle& pnh, const rt::Twin& twin)
      : pub_(pnh.advertise<regolith_twin::LandingOutcome>("landing", 10, true)) {}

  void after_step(const rt::Twin& twin, bool clock_due, bool force) override {
    const std::string phase = run(twin).phase(twin.ended());
    if (clock_due || phase != last_phase_) publish(twin);
    last_phase_ = phase;
  }

  void on_end(const rt::Twin& twin) override { publish(twin); }

  void markers(const rt::Twin& twin, const std::function<visualization_msgs::Marker(const std::string&, int)>& make,
               visualization_msgs::MarkerArray& out) override {
    const rt::LandingOutcome o = outcome(twin);
    auto mk = make("outcome", visualization_msgs::Marker::TEXT_VIEW_FACING);
    const rt::LandingSpec& sp = scene(twin).run_spec;
    mk.pose.position.z = sp.rim + 0.6;
    mk.scale.z = 0.06;
    mk.color.r = mk.color.g = mk.color.b = 1.0f;
    char text[256];
    std::snprintf(text, sizeof text, "t = %.2f s  %s  penetration %.1f cm  speed ratio %.3f", twin.state().time,
                  run(twin).phase(twin.ended()), 100 * o.max_penetration, o.speed_ratio);
    mk.text = text;
    out.markers.push_back(mk);
  }

 private:
  static const rt::LandingScene& scene(const rt::Twin& twin) {
    return static_cast<const rt::LandingScene&>(twin.scene());
  }
  static const rt::LandingRun& run(const rt::Twin& twin) { return static_cast<const rt::LandingRun&>(twin.run()); }
  static rt::LandingOutcome outcome(const rt::Twin& twin) { return run(twin).outcome(twin.report(), twin.ended()); }

  void publish(const rt::Twin& twin) {
    const rt::LandingOutcome o = outcome(twin);
    const rt::LandingRun& r = run(twin);
    regolith_twin::LandingOutcome msg;
    msg.header.stamp = stamp(twin.state().time);
    msg.phase = r.phase(twin.ended());
    msg.ended_by = o.ended_by;
    msg.contact = o.contact;
    msg.lifted_off = o.lifted_off;
    msg.cancelled_liftoffs = o.relandings;
    msg.t_contact = o.t_contact;
    msg.t_liftoff = o.t_liftoff;
    msg.v_in = o.v_in;
    msg.v_out = o.v_out;
    msg.speed_ratio = o.speed_ratio;
    msg.energy_ratio = o.energy_ratio;
    msg.angle_out_deg = o.angle_out_deg;
    msg.spin_out = o.spin_out;
    msg.collision_duration = o.collision_duration;
    msg.max_penetration = o.max_penetration;
    msg.travel_distance = o.travel_distance;
    msg.travel_time = o.travel_time;
    msg.ejected_volume = o.ejected_volume;
    msg.ejected_grains = o.ejected_grains;
    msg.lowest_corner = r.tracker().tracker().lowest_corner(twin.state().bodies[scene(twin).lander]);
    pub_.publish(msg);
  }

  ros::Publisher pub_;
  std::string last_phase_;
};

}  // namespace

std::unique_ptr<SceneTopics> make_landing_topics(ros::NodeHandle& pnh, const rt::Twin& twin) {
  return std::make_unique<LandingTopics>(pnh, twin);
}

}  // namespace rt_ros
