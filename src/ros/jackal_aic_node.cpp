/**
 * \file jackal_aic_node.cpp
 * \brief main() of the jackal_AIC node; everything else is in AicNode. Waits for rosout first
 *        (include/jackal_aic/ros/rosout_link.hpp), so the start-up lines reach /rosout.
 *        Exits with status 1 when the parameters are invalid.
 */
#include <ros/ros.h>

#include "jackal_aic/ros/aic_node.hpp"
#include "jackal_aic/ros/rosout_link.hpp"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "jackal_AIC");
  const ros::NodeHandle nh;  // starts the node: it registers and advertises /rosout
  if (!jackal_aic::node::waitForRosout())
  {
    ROS_WARN_STREAM("jackal_AIC: rosout did not connect within " << jackal_aic::node::kRosoutWait
                                                                 << " s: the start-up lines may be on stdout only");
  }
  jackal_aic::node::AicNode node{ nh, ros::NodeHandle("~") };
  if (!node.init())
  {
    return 1;
  }
  ros::spin();
  return 0;
}
