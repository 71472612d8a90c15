/**
 * \file twist_relay.cpp
 * \brief twist_relay: launch/robot.launch's stock path (controller:=stock), geometry_msgs/Twist
 *        from `in` to `out` unchanged, as twist_mux's output reaches the stock diff drive on an
 *        unmodified Jackal (doc/usage.md, 'On the robot').
 *
 * It advertises `out` at start-up, so the diff drive is connected before the first twist comes
 * and that twist is delivered (topic_tools' relay advertises on its first message, whose type it
 * needs, and that message goes out before any subscriber has connected: it is lost). Each twist
 * is forwarded from roscpp's network thread as it arrives (no spinner hand-over), TCP_NODELAY on
 * both sides. Topics: subscribes `in`, publishes `out` (remap both); no parameters.
 */
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>

#include "jackal_aic/ros/inline_callback_queue.hpp"

namespace
{
/// Forwards each twist of `in` to `out`, advertised at construction.
class TwistRelay
{
public:
  explicit TwistRelay(ros::NodeHandle nh) : out_(nh.advertise<geometry_msgs::Twist>("out", 10))
  {
    nh.setCallbackQueue(&queue_);
    in_ = nh.subscribe("in", 10, &TwistRelay::forward, this, ros::TransportHints().tcpNoDelay());
    ROS_INFO_STREAM("twist_relay: " << in_.getTopic() << " -> " << out_.getTopic());
  }

private:
  void forward(const geometry_msgs::Twist::ConstPtr& msg) { out_.publish(msg); }

  jackal_aic::node::InlineCallbackQueue queue_;  ///< `in`'s callbacks on roscpp's network thread
  ros::Publisher out_;
  ros::Subscriber in_;
};
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "twist_relay");
  TwistRelay relay{ ros::NodeHandle() };
  ros::spin();
  return 0;
}
