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
 *   aic_params --check FILE                     read a controller YAML like the node: unknown
 *                                               keys, type errors and violations; exit 1 on any
 *
 * Exit 0 on success, 1 on a bad file, 2 on bad arguments.
 */
#include <iostream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "jackal_tools/cli.hpp"
#include "jackal_tools/param_docs.hpp"
#include "jackal_aic/params/param_schema.hpp"
#include "jackal_tools/params_yaml.hpp"

using namespace jackal_aic;

namespace
{
/// Every key of a YAML file checked as the node would (both scopes): 0 if clean, 1 otherwise.
int checkFile(const std::string& file)
{
  YAML::Node root;
  try
  {
    root = YAML::LoadFile(file);
  }
  catch (const YAML::Exception& e)
  {
    std::cerr << "aic_params: " << file << ": " << e.what() << "\n";
    return 1;
  }
  NodeParams params;
  const ParamLoadReport report =
      loadParams(YamlParamSource(root), { ParamScope::kController, ParamScope::kNode }, false, &params);
  int problems = 0;
  for (const auto& key : report.unknown)
  {
    std::cerr << "aic_params: " << file << ": unknown key '" << key << "'\n";
    ++problems;
  }
  for (const auto& e : report.errors)
  {
    std::cerr << "aic_params: " << file << ": key '" << e.name << "' must be " << e.allowed << " (got " << e.value
              << ")\n";
    ++problems;
  }
  if (report.errors.empty())
  {
    for (const auto& v : params.validate())
    {
      std::cerr << "aic_params: " << file << ": " << v.toString() << "\n";
      ++problems;
    }
  }
  if (problems == 0)
  {
    std::cout << file << ": ok\n";
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
              "node and the tools do (e.g. --config config/default.yaml --config config/robot.yaml)");
  cl.option("check", &check, "check a YAML file (config/*.yaml) as the node reads it");
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
  if (!configs.empty() && !yaml)
  {
    return cl.bad("--config goes with --yaml");
  }
  if (!check.empty())
  {
    return checkFile(check);
  }
  if (!configs.empty())
  {
    try
    {
      const NodeParams values = loadNodeParamsFiles(configs);
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
