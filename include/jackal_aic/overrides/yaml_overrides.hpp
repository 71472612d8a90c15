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
namespace overrides
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

/**
 * \brief Flatten an overlay YAML map into "dotted.key=value" overrides (applyOverrides()),
 *        so an overlay file (only the keys that differ from a base file) and command-line
 *        --set overrides go through one parser.
 *
 * Maps descend ("motor: {speed_ki: 8}" -> "motor.speed_ki=8"); scalars, sequences and null
 * become the value, written as YAML flow ("[0, 0, 0.01]"). An empty map gives nothing.
 * \param overlay  a YAML map (or null: no overrides)
 * \param source   file name used in error messages
 * \throws std::invalid_argument "overlay '<source>' must be a YAML map" for any other root,
 *         or "overlay '<source>': key '<k>' contains '=' or '.'" for keys the override syntax
 *         cannot carry
 */
std::vector<std::string> overlayOverrides(const YAML::Node& overlay, const std::string& source);

/**
 * \brief overlayOverrides() of a YAML file.
 * \throws std::invalid_argument naming the file when it cannot be read, is malformed YAML or
 *         is not a map
 */
std::vector<std::string> loadOverlayFile(const std::string& path);

}  // namespace overrides
}  // namespace jackal_aic
