/// jackal_plant_node: the simulated Jackal (see plant_node.hpp).
#include <exception>
#include <iostream>

#include <ros/ros.h>

#include "plant_node.hpp"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "jackal_plant");
  try
  {
    jackal_aic::sim_nodes::PlantNode node(ros::NodeHandle(), ros::NodeHandle("~"));
    return node.run();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("jackal_plant: %s", e.what());
    // Also on stderr directly: the process exits at once, before rosout could carry it.
    std::cerr << "jackal_plant: fatal: " << e.what() << std::endl;
    return 1;
  }
}
