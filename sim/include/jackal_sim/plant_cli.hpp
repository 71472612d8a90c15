#pragma once
/**
 * \file plant_cli.hpp
 * \brief The plant options of the sim tools' command lines (plant_fit, plant_calibrate,
 *        plant_replay): --urdf, --config, --overlay (repeatable), --set (repeatable), and the
 *        loading of the robot model and the plant parameters they name. Header-only (the
 *        tools link Boost.program_options through jackal_aic/cli.hpp).
 */

#include <cstdio>
#include <string>
#include <vector>

#include "jackal_aic/cli.hpp"
#include "jackal_sim/plant_params.hpp"
#include "jackal_sim/robot_description.hpp"

namespace jackal_aic
{
namespace sim
{
/// What the plant options name; defaults: the package's URDF and plant YAML under `root`.
struct PlantOptions
{
  std::string urdf;                    ///< robot model
  std::string config;                  ///< plant YAML
  std::vector<std::string> overlays;   ///< plant YAMLs with only the keys that differ, in order
  std::vector<std::string> overrides;  ///< "dotted.key=value", after the overlays

  /// Defaults of a source tree or installed share folder `root` (sim/urdf/jackal.urdf, sim/config/plant.yaml).
  explicit PlantOptions(const std::string& root)
    : urdf(root + "/sim/urdf/jackal.urdf"), config(root + "/sim/config/plant.yaml")
  {
  }

  /// Register --urdf, --config, --overlay and --set on `cl` (bound to this object).
  void addTo(CommandLine* cl)
  {
    cl->option("urdf", &urdf, "robot model");
    cl->option("config", &config, "plant YAML");
    cl->repeated("overlay", &overlays, "plant YAML with only the keys that differ, after --config");
    cl->overrides("set", &overrides, "override a plant key, dotted");
  }

  /// The plant parameters: config, then the overlays, then the overrides (plantOverrides()).
  /// \throws PlantParamsError as loadPlantParams() and plantOverrides()
  PlantParams params() const { return loadPlantParams(config, plantOverrides(overlays, overrides)); }

  /// The robot model. \throws as loadRobotDescription()
  RobotDescription description() const { return loadRobotDescription(urdf); }

  /// Print the overlays and overrides, one "  overlay FILE" / "  override KEY=VALUE" line each.
  void printLayers() const
  {
    for (const auto& o : overlays)
    {
      std::printf("  overlay %s\n", o.c_str());
    }
    for (const auto& o : overrides)
    {
      std::printf("  override %s\n", o.c_str());
    }
  }
};

}  // namespace sim
}  // namespace jackal_aic
