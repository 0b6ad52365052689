// twin_node: runs a scenario or landing file as a ROS node (docs/ros.md).
#include <ros/ros.h>

#include "regolith_twin/ros/twin_node.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "twin_node");
  ros::NodeHandle nh, pnh("~");
  rt_ros::NodeParams p;
  try {
    p = rt_ros::read_params(pnh);
  } catch (const std::exception& e) {
    ROS_FATAL("twin_node: %s", e.what());
    return 2;
  }
  try {
    rt_ros::TwinNode node(nh, pnh, p);
    ros::AsyncSpinner spinner(2);
    spinner.start();
    node.start();
    ros::waitForShutdown();
    node.stop();
  } catch (const rt::InputError& e) {
    ROS_FATAL("twin_node: %s", e.what());
    return 2;
  } catch (const std::exception& e) {
    ROS_FATAL("twin_node: %s", e.what());
    return 1;
  }
  return 0;
}
