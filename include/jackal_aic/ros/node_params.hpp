#pragma once
/**
 * \file node_params.hpp
 * \brief Parameters of the jackal_AIC node: the controller's AicParams plus the node-only
 *        settings (timeouts, joint names, sensor pairing, set-point limits), read once
 *        from the private namespace and validated as a whole.
 */

#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "jackal_aic/params.hpp"

namespace jackal_aic
{
/// Largest loop rate the node accepts for either timer [Hz] (a roscpp timer reaches ~5 kHz here).
constexpr double kMaxLoopRate = 10000.0;

/**
 * \brief Everything the node reads from its private namespace.
 *
 * Keys are the member names (YAML keys of config/\*.yaml). Controller parameters live in
 * `aic` and keep the names of AicParams.
 */
struct NodeParams
{
  AicParams aic;  ///< controller parameters (thesis tables C-1 / 5-8); validated by AicParams::validate()

  double sensor_timeout = 0.25;     ///< no accepted sensor sample for this long -> zero command [s], > 0
  double set_point_timeout = 0.5;   ///< no set point for this long -> zero command [s], > 0
  /// Largest |stamp(imu) - stamp(joint_states)| for the two to form one sample [s], > 0.
  double imu_max_skew = 0.025;
  /// Samples closer than this to the previous one (by stamp) are dropped as duplicates [s], >= 0, < sensor_timeout.
  double min_sample_interval = 0.005;
  double max_linear_speed = 2.0;    ///< |set point linear.x| is clamped to this [m/s], > 0 (Jackal top speed)
  double max_angular_speed = 4.0;   ///< |set point angular.z| is clamped to this [rad/s], > 0 (stock controller limit)
  double runaway_hold_time = 1.0;   ///< after a runaway reset, zero command for this long [s], >= 0
  std::vector<std::string> left_joints;   ///< joints averaged into omega_L; required, non-empty
  std::vector<std::string> right_joints;  ///< joints averaged into omega_R; required, non-empty

  /**
   * \brief Every violated rule: the AicParams rules (AicParams::validate()), the node's
   *        limits (rates <= kMaxLoopRate), positive timeouts and limits, and joint names
   *        (non-empty lists, no empty or duplicate names, left and right disjoint).
   */
  std::vector<ParamViolation> validate() const;
};

/**
 * \brief Read every parameter of NodeParams from `pnh` (the private namespace).
 *
 * A missing key keeps the default of NodeParams (logged at INFO), except `left_joints`
 * and `right_joints`, which are required. A key of the wrong type (e.g. a string for
 * `tau`, a float for `embedding_order`) or an unknown `integrator` name is a violation.
 * Keys in the namespace that the node does not know are warned about (typos).
 *
 * \param pnh         private node handle (~)
 * \param params      output; holds defaults for missing keys
 * \param violations  output; type errors found while reading (append), before validate()
 */
void loadNodeParams(const ros::NodeHandle& pnh, NodeParams* params, std::vector<ParamViolation>* violations);

}  // namespace jackal_aic
