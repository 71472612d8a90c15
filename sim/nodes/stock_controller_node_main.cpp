/// stock_controller_node: the Jackal's stock velocity controller (see stock_controller_node.hpp).
#include <exception>
#include <iostream>

#include <ros/ros.h>

#include "stock_controller_node.hpp"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "stock_controller");
  try
  {
    jackal_aic::sim_nodes::StockControllerNode node{ ros::NodeHandle(), ros::NodeHandle("~") };
    ros::spin();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("stock_controller: %s", e.what());
    std::cerr << "stock_controller: fatal: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
