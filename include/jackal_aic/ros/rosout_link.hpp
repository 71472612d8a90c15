#pragma once
/**
 * \file rosout_link.hpp
 * \brief Waiting for the rosout node's connection before the node's first log lines
 *        (doc/jackal_aic_node.md, 'Start-up and /rosout').
 *
 * roscpp sends each log line to /rosout through its ROSOutAppender, whose publication is latched
 * with a queue of one message (ros_comm, clients/roscpp/src/libros/rosout_appender.cpp): a line
 * logged before the rosout node has connected reaches it only if it is the last one before the
 * connection. The node's start-up lines (an invalid parameter, another publisher on its output
 * topic, its summary) come within milliseconds of ros::start(), before rosout connects: without
 * the wait, all but the last reach only stdout.
 */

namespace jackal_aic
{
/// How long the node waits for rosout at start-up [s, wall time]: rosout connects within tens
/// of milliseconds of the node's registration; without a rosout node (a bare rosmaster) the node
/// starts after this, its start-up lines on stdout only.
constexpr double kRosoutWait = 2.0;

/**
 * \brief Block until the rosout node subscribes to this node's /rosout (the connection is up, so
 *        the lines logged from then on reach it), or `timeout` [s, wall time] passes, or ROS shuts
 *        down. Polls roscpp's TopicManager every 5 ms. Call after ros::start() (a NodeHandle).
 * \param timeout  [s], >= 0 (0: ask once)
 * \return true if rosout is connected
 */
bool waitForRosout(double timeout = kRosoutWait);
}  // namespace jackal_aic
