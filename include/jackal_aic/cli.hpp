#pragma once
/**
 * \file cli.hpp
 * \brief Command lines of the C++ tools (aic_analyze, aic_step_metrics, aic_params,
 *        closed_loop_run, plant_fit, plant_calibrate), all on CLI11, with one convention:
 *        --help prints the usage and exits 0; a bad argument prints "<tool>: error: <what>"
 *        and the usage to stderr and exits 2. Header-only; needs CLI11 (libcli11-dev).
 */

#include <cmath>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace jackal_aic
{
/// Exit status of a tool for bad arguments.
constexpr int kExitBadArguments = 2;

/**
 * \brief Parse the command line.
 * \param app   the tool's options
 * \param argc, argv  as given to main()
 * \return -1 to go on; otherwise the exit status for main() (0 after --help, kExitBadArguments
 *         after a parse error, with the message and the usage printed)
 */
inline int parseCommandLine(CLI::App& app, int argc, char** argv)
{
  try
  {
    app.parse(argc, argv);
  }
  catch (const CLI::ParseError& e)
  {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success))
    {
      return app.exit(e);  // --help
    }
    std::cerr << app.get_name() << ": error: " << e.what() << "\n" << app.help();
    return kExitBadArguments;
  }
  return -1;
}

/**
 * \brief Report a bad argument found after parsing (a value out of its range, a choice
 *        that does not exist): prints "<tool>: error: <message>" and the usage.
 * \return kExitBadArguments, for main() to return
 */
inline int badArgument(const CLI::App& app, const std::string& message)
{
  std::cerr << app.get_name() << ": error: " << message << "\n" << app.help();
  return kExitBadArguments;
}

/**
 * \brief Add a repeatable "--NAME KEY=VALUE" override option (one value per occurrence);
 *        the texts are parsed by parseOverride() / applyOverrides()
 *        (include/jackal_aic/yaml_overrides.hpp), the one override parser of the tools.
 */
inline CLI::Option* addOverrideOption(CLI::App& app, const std::string& name, std::vector<std::string>* overrides,
                                      const std::string& what)
{
  return app.add_option(name, *overrides, what)->type_name("KEY=VALUE")->allow_extra_args(false);
}

/// A CLI11 check that a number is finite (rejects nan, inf).
inline CLI::Validator finiteNumber()
{
  return CLI::Validator(
      [](std::string& text) {
        const double v = std::strtod(text.c_str(), nullptr);
        return std::isfinite(v) ? std::string() : "'" + text + "' is not a finite number";
      },
      "FINITE");
}

/**
 * \brief A number as JSON text, the tools' machine-readable output: `precision` significant
 *        digits, and `null` for NaN or +-Inf (JSON has no such numbers; a metric that is
 *        undefined, such as the settling time of a response that never settles, is NaN).
 */
inline std::string jsonNumber(double v, int precision = 6)
{
  if (!std::isfinite(v))
  {
    return "null";
  }
  std::ostringstream os;
  os.precision(precision);
  os << v;
  return os.str();
}

}  // namespace jackal_aic
