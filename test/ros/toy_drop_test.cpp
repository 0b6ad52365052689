// A scene kind's own topic, added from outside the node: the toy drop kind of
// test/support/toy_drop.hpp registers itself and a topic ~above (grains
// above its plane, std_msgs/UInt32) from this test; a TwinNode runs the toy
// scene to its end and the last message equals the run's own count.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_msgs/UInt32.h>
#include <unistd.h>

#include <atomic>
#include <memory>

#include "regolith_twin/ros/scene_topics.hpp"
#include "regolith_twin/ros/twin_node.hpp"
#include "toy_drop.hpp"

namespace {

// The toy's topic: its RegionCount after every step at the clock rate, and at the end.
class DropTopics : public rt_ros::SceneTopics {
 public:
  explicit DropTopics(ros::NodeHandle& pnh) : pub_(pnh.advertise<std_msgs::UInt32>("above", 10, true)) {}
  void after_step(const rt::Twin& twin, bool clock_due, bool force) override {
    if (clock_due) publish(twin);
  }
  void on_end(const rt::Twin& twin) override { publish(twin); }

 private:
  void publish(const rt::Twin& twin) {
    std_msgs::UInt32 m;
    m.data = uint32_t(dynamic_cast<const toy::DropRun&>(twin.run()).above().grains());
    pub_.publish(m);
  }
  ros::Publisher pub_;
};

std::atomic<long> g_messages{0};
std::atomic<long> g_last{-1};
void on_above(const std_msgs::UInt32::ConstPtr& m) {
  g_last = m->data;
  ++g_messages;
}

}  // namespace

TEST(ToyDropNode, TheKindsTopicFollowsItsRun) {
  ros::NodeHandle nh, pnh("~");
  const std::string file = "/tmp/regolith_toy_drop_node_" + std::to_string(::getpid()) + ".yaml";
  toy::write_drop_file(file);
  rt_ros::NodeParams p;
  p.scenario_file = file;
  p.threads = 1;
  ros::Subscriber sub = pnh.subscribe("above", 100, on_above);
  rt_ros::TwinNode node(nh, pnh, p);
  node.start();
  for (int k = 0; k < 6000 && !node.ended(); ++k) ros::WallDuration(0.01).sleep();
  ASSERT_TRUE(node.ended()) << "the toy run did not end in 60 s";
  ros::WallDuration(0.5).sleep();  // the end message delivered
  node.stop();
  EXPECT_GT(g_messages.load(), 1);
  EXPECT_EQ(g_last.load(), 0) << "after the drop no grain is above the plane";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "toy_drop_node");
  rt::register_scene_kind(std::make_shared<toy::DropKind>());
  rt_ros::register_scene_topics("drop", [](ros::NodeHandle& pnh, const rt::Twin&) {
    return std::make_unique<DropTopics>(pnh);
  });
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int rc = RUN_ALL_TESTS();
  ros::shutdown();
  return rc;
}
