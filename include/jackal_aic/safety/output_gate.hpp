#pragma once
/**
 * \file output_gate.hpp
 * \brief Whether the jackal_AIC node's wheel commands leave the node (its ~enable_output
 *        service): ROS-free, so the rule is tested without a roscore (test/unit/safety/test_output_gate.cpp).
 *
 * A field trial alternates the AIC with the stock controller on a live robot
 * (doc/field_trials.md): while another controller drives, the AIC's output is disabled, so the
 * diff drive never gets two command streams. Disabled, the node publishes nothing on its command
 * topic (every command the loop produces is counted and dropped); enabled again, the controller
 * restarts from the measured state (ControlLoop::restartFromMeasured(): beliefs at the measured
 * twist, action at the measured wheel speeds), so the switch is bumpless whatever the action
 * integrated while another controller moved the robot.
 *
 * The gate is one condition of its own on the output path; other conditions (a publisher
 * conflict, the final finiteness guard) are independent of it. Not thread-safe: the node calls
 * it under its lock.
 */

#include <cstdint>

namespace jackal_aic
{
namespace safety
{
/// The output gate (see the file comment). Starts enabled: a node without a field trial is unchanged.
class OutputGate
{
public:
  /// What a call of set() changed.
  struct Change
  {
    bool changed = false;  ///< the gate's state changed
    bool enabled = true;   ///< the state after the call
    /// Disabled -> enabled: restart the controller from the measured state before the next command.
    bool restart = false;
  };

  /**
   * \brief Enable or disable the output.
   * \param enabled  true: commands leave the node; false: they are dropped
   * \return the change (a repeated request changes nothing and restarts nothing)
   */
  Change set(bool enabled)
  {
    Change c;
    c.changed = enabled != enabled_;
    c.restart = c.changed && enabled;
    c.enabled = enabled;
    if (c.changed)
    {
      enabled_ = enabled;
      ++switches_;
    }
    return c;
  }

  /// True while commands leave the node.
  bool enabled() const { return enabled_; }

  /**
   * \brief A command is about to be published.
   * \return true to publish it; false (the command counted as suppressed) while disabled
   */
  bool admit()
  {
    if (enabled_)
    {
      return true;
    }
    ++suppressed_;
    return false;
  }

  /// Commands dropped while disabled, since construction.
  std::uint64_t suppressed() const { return suppressed_; }
  /// Changes of state since construction.
  std::uint64_t switches() const { return switches_; }

private:
  bool enabled_ = true;
  std::uint64_t suppressed_ = 0;
  std::uint64_t switches_ = 0;
};

}  // namespace safety
}  // namespace jackal_aic
