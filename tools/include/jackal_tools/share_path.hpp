#pragma once
/**
 * \file share_path.hpp
 * \brief Where the installed programs find the package's data (the URDF, the plant and
 *        controller YAML, the tracking profiles) at run time: the one lookup of every tool.
 */

#include <string>

namespace jackal_aic
{
/**
 * \brief The package's data folder, looked up at run time, in this order:
 *   1. the environment variable `JACKAL_AIC_SHARE`, if set and not empty;
 *   2. `ros::package::getPath("jackal_aic")` (roslib, over `ROS_PACKAGE_PATH`): the package's
 *      source folder in a devel space, `<install>/share/jackal_aic` in an install space; the
 *      package's `setup.bash` sets it;
 *   3. the current directory ".", so a program run from the repository root finds its data.
 * Never throws; a file missing there is reported by the loader that opens it.
 * \return a folder path without a trailing '/'
 */
std::string packageShareDir();

/**
 * \brief A data file of the package: `packageShareDir() + "/" + relative`.
 * \param relative  a path below the package's folder, e.g. "sim/urdf/jackal.urdf"
 */
std::string packageFile(const std::string& relative);
/**
 * \brief A data file named on a command line: `path` itself when it can be opened; otherwise, for
 *        a relative path, packageFile(path) when that can be opened (so `config/default.yaml`
 *        works from any folder); otherwise `path` unchanged, for the loader to report. Never throws.
 */
std::string resolveDataFile(const std::string& path);

}  // namespace jackal_aic
