/**
 * \file share_path.cpp
 * \brief The package's data folder at run time (jackal_tools/share_path.hpp).
 */
#include "jackal_tools/share_path.hpp"

#include <cstdlib>
#include <fstream>

#include <ros/package.h>

namespace jackal_aic
{
std::string packageShareDir()
{
  const char* env = std::getenv("JACKAL_AIC_SHARE");
  if (env != nullptr && env[0] != '\0')
  {
    return env;
  }
  const std::string found = ros::package::getPath("jackal_aic");
  return found.empty() ? std::string(".") : found;
}

std::string packageFile(const std::string& relative)
{
  return packageShareDir() + "/" + relative;
}

std::string resolveDataFile(const std::string& path)
{
  if (path.empty() || std::ifstream(path).good() || path.front() == '/')
  {
    return path;
  }
  const std::string in_package = packageFile(path);
  return std::ifstream(in_package).good() ? in_package : path;
}

}  // namespace jackal_aic
