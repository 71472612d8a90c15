#pragma once
/**
 * \file params_yaml.hpp
 * \brief Read a jackal_AIC YAML file (config/\*.yaml) outside ROS: its controller keys into
 *        AicParams (aic_analyze, aic_predict, plant_fit), or every key into NodeParams
 *        (closed_loop_run). ROS-free; yaml-cpp only.
 *
 * Keys, types and defaults are those of the parameter schema
 * (include/jackal_aic/params/param_schema.hpp); the node reads the same files through rosparam
 * (src/ros/param_server.cpp). loadAicParams() skips node-only keys; unknown keys are reported.
 */

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "jackal_aic/params/param_schema.hpp"
#include "jackal_aic/params/aic_params.hpp"

namespace jackal_aic
{
/**
 * \brief A parsed YAML map as a ParamSource: kDouble accepts any number (an integer too),
 *        kInt an integer, kBool true/false, lists sequences of those.
 */
class YamlParamSource : public params::ParamSource
{
public:
  /// \param root  the file's top-level map (a non-map has no keys)
  explicit YamlParamSource(YAML::Node root) : root_(std::move(root)) {}
  Status read(const std::string& key, params::ParamType type, params::ParamValue* out) const override;
  std::string raw(const std::string& key) const override;
  std::vector<std::string> keys() const override;

private:
  YAML::Node root_;
};

/**
 * \brief A YAML file's top-level map (the file found as resolveDataFile() finds it) with the
 *        "key=value" overrides applied (applyOverrides()).
 * \throws std::runtime_error naming the file on an unreadable file, a YAML error, an empty file,
 *         a top level that is not a map, or a malformed override
 */
YAML::Node readYamlMap(const std::string& file, const std::vector<std::string>& overrides = {});

/**
 * \brief Controller parameters from a parsed YAML map (absent keys keep AicParams' defaults).
 * \param root       the file's top-level map
 * \param file       the file's name, for messages
 * \param defaulted  out: controller keys absent from the file (their defaults were used); may be null
 * \param unknown    out: keys that are in no scope of the schema (typos); may be null
 * \return the parameters, not validated (call AicParams::validate())
 * \throws std::runtime_error "<file>: key '<key>' must be <type> (got <value>)" on a value of
 *         the wrong type or an unknown integrator name (the first such key)
 */
params::AicParams aicParamsFromYaml(const YAML::Node& root, const std::string& file,
                                    std::vector<std::string>* defaulted, std::vector<std::string>* unknown);

/**
 * \brief As aicParamsFromYaml() from a file, with "key=value" overrides (applyOverrides(),
 *        include/jackal_aic/overrides/yaml_overrides.hpp) applied on top, and validated.
 * \throws std::runtime_error on an unreadable file, a YAML error, a malformed override, a value of
 *         the wrong type, or invalid parameters (every violation listed)
 */
params::AicParams loadAicParams(const std::string& file, const std::vector<std::string>& overrides = {});

/**
 * \brief Every key of the schema (controller and node) from YAML files read in order, each
 *        over the previous (config/default.yaml, then an overlay such as config/robot.yaml),
 *        the "key=value" overrides applied to the last; absent keys keep the schema's defaults.
 *        For the tools that run the node's logic headless (closed_loop_run). A controller that
 *        is unstable on the linear model at its rates (stabilityWarning(),
 *        jackal_aic/analysis/configured_stability.hpp) is loaded all the same, with one line
 *        "<files>: warning: the configuration is unstable on the linear model ... spectral radius
 *        R >= 1 ..." on stderr, as the node warns (doc/tuning.md, 'The stability check at load').
 *        A key of the last file or of the overrides that the loaded belief model does not read
 *        (params::keysWithoutEffect()) gives one line "<files>: warning: KEY = VALUE has no effect
 *        with belief_model M (...)" each.
 * \param files      at least one YAML file
 * \param overrides  applied on top of the last file
 * \param warn       false: neither warning (the files are the bases of another, which is judged on its own)
 * \return the parameters, validated except that both joint lists may be empty (for the caller to fill)
 * \throws std::runtime_error on an unreadable file, a YAML error, a malformed override, a value
 *         of the wrong type (naming the file and key), or invalid parameters (every violation)
 */
params::NodeParams loadNodeParamsFiles(const std::vector<std::string>& files,
                                       const std::vector<std::string>& overrides = {}, bool warn = true);

}  // namespace jackal_aic
