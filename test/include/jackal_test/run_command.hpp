#pragma once
/**
 * \file run_command.hpp
 * \brief The tests' way to run one of the package's programs: a shell command's exit status and
 *        its output (stdout and stderr together). Header-only, POSIX popen.
 */

#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace jackal_test
{
/// What a command did.
struct CommandResult
{
  int code;         ///< exit status, or -1 when it could not run or did not exit normally
  std::string out;  ///< stdout and stderr
};

/**
 * \brief Run `command` through /bin/sh with stderr joined to stdout and wait for it.
 * \return its exit status and output; code -1 when the shell could not be started or the
 *         command ended by a signal.
 */
inline CommandResult runCommand(const std::string& command)
{
  CommandResult r{ -1, "" };
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr)
  {
    return r;
  }
  char buf[512];
  while (fgets(buf, sizeof(buf), pipe) != nullptr)
  {
    r.out += buf;
  }
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}
}  // namespace jackal_test
