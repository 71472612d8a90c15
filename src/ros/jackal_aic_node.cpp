/**
 * \file jackal_aic_node.cpp
 * \brief main() of the jackal_AIC node; everything else is in AicNode.
 *        Exits with status 1 when the parameters are invalid.
 */
#include <ros/ros.h>

#include "jackal_aic/ros/aic_node.hpp"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "jackal_AIC");
  jackal_aic::AicNode node{ ros::NodeHandle(), ros::NodeHandle("~") };
  if (!node.init())
  {
    return 1;
  }
  ros::spin();
  return 0;
}
