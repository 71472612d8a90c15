#pragma once
/**
 * \file yaml_overrides.hpp
 * \brief The one parser of "KEY=VALUE" overrides on top of a YAML file, shared by every
 *        command line and loader (aic_analyze --set, loadAicParams(), closed_loop_run
 *        --set / --aic-set, plant_fit, plant_calibrate, the plant node's ~overrides).
 *        ROS-free; yaml-cpp only.
 */

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace jackal_aic
{
/// One parsed override: a (possibly dotted) key and its value text.
struct Override
{
  std::string key;    ///< e.g. "tau" or "motor.command_delay" (dots descend into maps)
  std::string value;  ///< the text after the first '=', parsed as YAML when applied
};

/**
 * \brief Split "key=value" at the first '='.
 * \param text  the override, e.g. "var_y=[2, 20, 1e5, 1e5]"
 * \throws std::invalid_argument "override '<text>' is not of the form key=value" if there is
 *         no '=', the key is empty, or a dotted key has an empty part ("a..b", ".a", "a.")
 */
Override parseOverride(const std::string& text);

/**
 * \brief Parse every override first (parseOverride()), then apply them in order to `root`.
 *
 * The value is parsed as YAML ("0.01" a number, "[1, 2]" a list, "exact" a string); a dotted
 * key "a.b.c" sets root[a][b][c], creating the maps on the way. Later overrides win.
 * \param root       the file's top-level map (modified in place; yaml-cpp nodes are handles)
 * \param overrides  "key=value" strings
 * \throws std::invalid_argument "override '<text>' is not of the form key=value" or
 *         "override '<text>' has a malformed value" (nothing is applied then)
 */
void applyOverrides(YAML::Node root, const std::vector<std::string>& overrides);

}  // namespace jackal_aic
