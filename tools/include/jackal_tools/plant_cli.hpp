#pragma once
/**
 * \file plant_cli.hpp
 * \brief The plant options of the sim tools' command lines (plant_fit, plant_calibrate,
 *        plant_replay, closed_loop_run): --urdf, --config, --overlay (repeatable), --set (repeatable), and the
 *        loading of the robot model and the plant parameters they name. Header-only (the
 *        tools link Boost.program_options through jackal_tools/cli.hpp).
 */

#include <cstdio>
#include <string>
#include <vector>

#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"
#include "jackal_tools/cli.hpp"
#include "jackal_tools/share_path.hpp"

namespace jackal_aic
{
/// What the plant options name; defaults: the package's URDF and plant YAML (packageFile()).
struct PlantOptions
{
  std::string urdf;                    ///< robot model
  std::string config;                  ///< plant YAML
  std::vector<std::string> overlays;   ///< plant YAMLs with only the keys that differ, in order
  std::vector<std::string> overrides;  ///< "dotted.key=value", after the overlays

  /// The package's sim/urdf/jackal.urdf and sim/config/plant.yaml (packageFile()).
  PlantOptions() : urdf(packageFile("sim/urdf/jackal.urdf")), config(packageFile("sim/config/plant.yaml")) {}

  /// Register --urdf, --config, --overlay and --set on `cl` (bound to this object).
  void addTo(CommandLine* cl)
  {
    cl->option("urdf", &urdf, "robot model");
    cl->option("config", &config, "plant YAML");
    cl->repeated("overlay", &overlays, "plant YAML with only the keys that differ, after --config");
    cl->overrides("set", &overrides, "override a plant key, dotted");
  }

  /// The plant parameters: config, then the overlays, then the overrides (plantOverrides()).
  /// \throws plant::PlantParamsError as loadPlantParams() and plantOverrides()
  plant::PlantParams params() const
  {
    return plant::loadPlantParams(config, plant::plantOverrides(overlays, overrides));
  }

  /// The robot model. \throws as loadRobotDescription()
  plant::RobotDescription description() const { return plant::loadRobotDescription(urdf); }

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

}  // namespace jackal_aic
