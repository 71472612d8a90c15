#pragma once
/**
 * \file params_yaml.hpp
 * \brief Read the controller keys of a jackal_AIC YAML file (config/*.yaml) into AicParams,
 *        outside ROS (aic_analyze, plant_identify). ROS-free; yaml-cpp only.
 *
 * The node reads the same files through rosparam (src/ros/node_params.cpp); node-only keys
 * (timeouts, joint names, ...) are skipped here, unknown keys are reported.
 */

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "jackal_aic/params.hpp"

namespace jackal_aic
{
/**
 * \brief Controller parameters from a parsed YAML map (absent keys keep AicParams' defaults).
 * \param root       the file's top-level map
 * \param file       the file's name, for messages
 * \param defaulted  out: keys absent from the file (their defaults were used); may be null
 * \param unknown    out: keys that are neither controller nor node-only keys; may be null
 * \return the parameters, not validated (call AicParams::validate())
 * \throws std::runtime_error "<file>: key '<key>' must be <type>" on a value of the wrong type,
 *         or on an unknown integrator name
 */
AicParams aicParamsFromYaml(const YAML::Node& root, const std::string& file, std::vector<std::string>* defaulted,
                            std::vector<std::string>* unknown);

/**
 * \brief As aicParamsFromYaml() from a file, with "key=value" overrides (value parsed as YAML)
 *        applied on top, and validated.
 * \throws std::runtime_error on an unreadable file, a YAML error, a malformed override, a value of
 *         the wrong type, or invalid parameters (every violation listed)
 */
AicParams loadAicParams(const std::string& file, const std::vector<std::string>& overrides = {});

}  // namespace jackal_aic
