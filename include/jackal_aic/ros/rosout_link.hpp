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
namespace node
{
/// How long the node waits at most for a /rosout subscriber's connection at start-up [s, wall
/// time]: rosout connects within tens of milliseconds of the node's registration; one that does
/// not answer (a hung rosout) delays the start by this, its start-up lines then on stdout only.
constexpr double kRosoutWait = 2.0;

/**
 * \brief If the master lists a subscriber of /rosout (the rosout node; rostest runs none), block
 *        until one is connected to this node's /rosout (the lines logged from then on reach it),
 *        or `timeout` [s, wall time] passes, or ROS shuts down; polls roscpp's TopicManager every
 *        5 ms. Without a listed subscriber (or when the master cannot be asked) return at once:
 *        there is nothing to wait for. Call after ros::start() (a NodeHandle).
 * \param timeout  [s], >= 0 (0: ask once)
 * \return false if a listed subscriber did not connect within `timeout` (or ROS shut down),
 *         true otherwise
 */
bool waitForRosout(double timeout = kRosoutWait);
}  // namespace node
}  // namespace jackal_aic
