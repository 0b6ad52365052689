// regolith_bag_outcome: the landing outcome recomputed from a recorded run.
//   regolith_bag_outcome BAG LANDING.yaml [--set key=value]... [--topic T] [--body NAME] [--out FILE.json]
// Reads the body states of the bag (published every step), feeds the
// lander's states and contact counts to the same LandingTracker the engine
// uses, and writes the body-derived outcome (contact, lift-off, ratios,
// penetration, travel) as JSON. The landing file gives the lander's mass,
// inertia and box and the outcome definitions (trim plane, run end).
// Exit codes: 0 done, 2 bad input, 4 the recording has gaps (throttled or lost messages).
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_eigen/tf2_eigen.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <string>
#include <vector>

#include "regolith_twin/BodyStates.h"
#include "regolith_twin/scenes/landing/landing.hpp"
#include "regolith_twin/run/series.hpp"
#include "regolith_twin/io/scenario.hpp"

int main(int argc, char** argv) {
  std::string bag_path, file, topic = "/twin_node/body_states", body, out;
  std::vector<std::string> overrides;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "regolith_bag_outcome: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--set") overrides.push_back(value());
    else if (a == "--topic") topic = value();
    else if (a == "--body") body = value();
    else if (a == "--out") out = value();
    else if (bag_path.empty()) bag_path = a;
    else if (file.empty()) file = a;
    else {
      std::fprintf(stderr, "usage: regolith_bag_outcome BAG LANDING.yaml [--set k=v]... [--topic T] [--body NAME] [--out F]\n");
      return 2;
    }
  }
  if (bag_path.empty() || file.empty()) {
    std::fprintf(stderr, "usage: regolith_bag_outcome BAG LANDING.yaml [--set k=v]... [--topic T] [--body NAME] [--out F]\n");
    return 2;
  }
  try {
    YAML::Node root = rt::load_document(file, overrides);
    const rt::LandingSpec spec = rt::parse_landing(root["landing"], file);
    root.remove("landing");
    const rt::Scenario sc = rt::parse_scenario(root, file);
    if (body.empty()) body = spec.lander;
    int b = -1;
    for (size_t k = 0; k < sc.model.bodies.size(); ++k)
      if (sc.model.bodies[k].name == body) b = int(k);
    if (b < 0) throw rt::InputError(file + ": no body named '" + body + "'");
    const rt::BodyModel& bm = sc.model.bodies[b];

    rosbag::Bag bag;
    try {
      bag.open(bag_path, rosbag::bagmode::Read);
    } catch (const std::exception& e) {
      throw rt::InputError(bag_path + ": cannot read the bag (" + e.what() + ")");
    }
    rosbag::View view(bag, rosbag::TopicQuery(topic));
    if (view.size() == 0) throw rt::InputError(bag_path + ": no messages on " + topic);
    rt::LandingTracker tracker(bm, spec, rt::landing_gravity(spec), 0.0);
    long last_step = -1, messages = 0;
    double t = 0;
    bool first = true;
    for (const rosbag::MessageInstance& mi : view) {
      const auto msg = mi.instantiate<regolith_twin::BodyStates>();
      if (!msg) continue;
      ++messages;
      if (!first && msg->step != last_step + 1) {
        std::fprintf(stderr,
                     "regolith_bag_outcome: step %ld follows step %ld: the recording is not every step "
                     "(~body_state_rate > 0, or messages were lost); the outcome cannot be recomputed exactly\n",
                     long(msg->step), last_step);
        return 4;
      }
      first = false;
      last_step = msg->step;
      t = msg->header.stamp.toSec();
      const regolith_twin::BodyState* st = nullptr;
      for (const auto& x : msg->bodies)
        if (x.name == body) st = &x;
      if (!st) throw rt::InputError(bag_path + ": body '" + body + "' missing from " + topic);
      // The state before the first step (published at start-up) may be fed
      // too: the lander is placed clear of the bed, so it changes nothing.
      rt::BodyState bs;
      rt::Quat q_ref;
      rt::Vec3 v, w;
      tf2::fromMsg(st->pose.orientation, q_ref);
      tf2::fromMsg(st->center_of_mass, bs.pos);
      tf2::fromMsg(st->twist.linear, v);
      tf2::fromMsg(st->twist.angular, w);
      bs.q = (q_ref * bm.ref_rot).normalized();
      rt::set_body_velocity(bm, bs, v, w);
      rt::BodyContacts c;
      c.total = st->contacts;
      c.bed = st->bed_contacts;
      if (tracker.update(t, bs, c)) break;
    }
    tracker.finish(t);
    const rt::LandingOutcome& o = tracker.outcome();
    rt::JsonObject oc;
    rt::landing_outcome_json(o, oc);
    rt::JsonObject j;
    j.str("bag", bag_path).str("file", file).str("body", body).num("messages", double(messages));
    j.obj("outcome", oc);
    if (out.empty()) std::printf("%s\n", j.dump(2).c_str());
    else j.write(out);
    if (!tracker.ended())
      std::fprintf(stderr, "regolith_bag_outcome: the recording stops before the run end (outcome so far)\n");
    return 0;
  } catch (const rt::InputError& e) {
    std::fprintf(stderr, "regolith_bag_outcome: error: %s\n", e.what());
    return 2;
  }
}
