/**
 * \file aic_params.cpp
 * \brief CLI: print what is generated from the parameter schema
 *        (include/jackal_aic/params/param_schema.hpp, tools/include/jackal_tools/param_docs.hpp):
 *
 *   aic_params --cfg        > cfg/AIC.cfg       the dynamic_reconfigure definition
 *   aic_params --markdown                       the parameter table of doc/jackal_aic_node.md
 *   aic_params --yaml                           every key with its default, commented
 *   aic_params --yaml --config F [--config G]   every key as the node reads F, then G, over the
 *                                               defaults (the effective configuration)
 *   aic_params --check FILE [--config BASE ...] read a controller YAML like the node (over its
 *                                               bases; an overlay without joint lists over
 *                                               config/default.yaml + config/robot.yaml): unknown
 *                                               keys, type errors and violations; exit 1 on any;
 *                                               a valid controller unstable on the linear model at
 *                                               its rates: a warning on stderr, exit 0 (as the node)
 * A relative file that is not found is looked up in the package (jackal_tools/share_path.hpp).
 *
 * Exit 0 on success, 1 on a bad file, 2 on bad arguments.
 */
#include <iostream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "jackal_tools/cli.hpp"
#include "jackal_tools/param_docs.hpp"
#include "jackal_aic/analysis/configured_stability.hpp"
#include "jackal_aic/params/param_schema.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_tools/share_path.hpp"

using namespace jackal_aic;

namespace
{
/// The files the robot loads before an overlay (doc/usage.md, 'On the robot').
const std::vector<std::string> kOverlayBases = { "config/default.yaml", "config/robot.yaml" };

/**
 * Every key of a YAML file checked as the node would (both scopes), loaded over `bases` in order:
 * 0 if clean, 1 otherwise. With no bases, a file that sets neither joint list is an overlay and is
 * checked over kOverlayBases (from the package), as the robot loads it; that is said on stdout.
 */
int checkFile(const std::string& given, std::vector<std::string> bases)
{
  const std::string file = resolveDataFile(given);
  YAML::Node root;
  try
  {
    root = YAML::LoadFile(file);
  }
  catch (const YAML::Exception& e)
  {
    std::cerr << "aic_params: " << given << ": " << e.what() << "\n";
    return 1;
  }
  if (root.IsNull())
  {
    std::cerr << "aic_params: " << given << ": no parameters (the file is empty or holds only comments)\n";
    return 1;
  }
  if (!root.IsMap())
  {
    std::cerr << "aic_params: " << given << ": expected a map of parameters at the top level\n";
    return 1;
  }
  if (bases.empty() && !root["left_joints"] && !root["right_joints"])
  {
    bases = kOverlayBases;
    std::cout << given << ": an overlay (no joint lists): checked over " << bases[0] << " + " << bases[1] << "\n";
  }
  params::NodeParams params;
  try
  {
    if (!bases.empty())
    {
      params = loadNodeParamsFiles(bases, {}, /*warn=*/false);  // the checked file is judged, not its bases
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "aic_params: a base of " << given << ": " << e.what() << "\n";
    return 1;
  }
  const params::ParamLoadReport report = params::loadParams(
      YamlParamSource(root), { params::ParamScope::kController, params::ParamScope::kNode }, false, &params);
  int problems = 0;
  for (const auto& key : report.unknown)
  {
    std::cerr << "aic_params: " << given << ": unknown key '" << key << "'\n";
    ++problems;
  }
  for (const auto& e : report.errors)
  {
    std::cerr << "aic_params: " << given << ": key '" << e.name << "' must be " << e.allowed << " (got " << e.value
              << ")\n";
    ++problems;
  }
  if (report.errors.empty())
  {
    for (const auto& v : params.validate())
    {
      std::cerr << "aic_params: " << given << ": " << v.toString() << "\n";
      ++problems;
    }
  }
  if (problems == 0)
  {
    // Valid: loaded as the node loads it, with the node's warning of an unstable controller.
    const std::string unstable = analysis::stabilityWarning(params.aic);
    if (!unstable.empty())
    {
      std::cerr << "aic_params: " << given << ": warning: the configuration is " << unstable << "\n";
    }
    for (const params::ParamSpec* row : params::keysWithoutEffect(params, YamlParamSource(root).keys()))
    {
      std::cerr << "aic_params: " << given << ": warning: " << params::withoutEffectText(*row, params) << "\n";
    }
    std::cout << given << ": ok\n";
  }
  return problems == 0 ? 0 : 1;
}
}  // namespace

int main(int argc, char** argv)
{
  bool cfg = false;
  bool markdown = false;
  bool yaml = false;
  std::string check;
  std::vector<std::string> configs;
  CommandLine cl("aic_params", "Print what is generated from the jackal_AIC parameter schema, or check a YAML against "
                               "it.");
  cl.flag("cfg", &cfg, "cfg/AIC.cfg (dynamic_reconfigure), generated");
  cl.flag("markdown", &markdown, "the parameter table of doc/jackal_aic_node.md");
  cl.flag("yaml", &yaml, "every key with its default, as a commented YAML file");
  cl.repeated("config", &configs,
              "with --yaml: print the values after loading these YAML files in order over the defaults, as the "
              "node and the tools do (e.g. --config config/default.yaml --config config/robot.yaml); with "
              "--check: the files loaded before the checked one. A relative path not found is looked up in the "
              "package");
  cl.option("check", &check,
            "check a YAML file (config/*.yaml) as the node reads it; an overlay (a file without the joint lists) "
            "is checked over config/default.yaml and config/robot.yaml unless --config names its bases");
  cl.footer("Give exactly one of --cfg, --markdown, --yaml and --check. Exit 0 on success, 1 on a bad file, 2 on "
            "bad arguments.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  if (int(cfg) + int(markdown) + int(yaml) + int(cl.given("check")) != 1)
  {
    return cl.bad("give exactly one of --cfg, --markdown, --yaml and --check");
  }
  if (!configs.empty() && !yaml && !cl.given("check"))
  {
    return cl.bad("--config goes with --yaml or --check");
  }
  if (!check.empty())
  {
    return checkFile(check, configs);
  }
  if (!configs.empty())
  {
    try
    {
      const params::NodeParams values = loadNodeParamsFiles(configs);
      std::cout << parameterYaml(&values, configs);
    }
    catch (const std::exception& e)
    {
      std::cerr << "aic_params: " << e.what() << "\n";
      return 1;
    }
    return 0;
  }
  std::cout << (cfg ? reconfigureCfgScript() : markdown ? parameterTableMarkdown() : parameterYamlTemplate());
  return 0;
}
