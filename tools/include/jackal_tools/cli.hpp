#pragma once
/**
 * \file cli.hpp
 * \brief Command lines of the C++ tools (aic_analyze, aic_step_metrics, aic_params, aic_predict,
 *        aic_timing, closed_loop_run, plant_fit, plant_calibrate), all on Boost.program_options
 *        (rosdep key `boost`, which every ROS 1 machine has), with one convention:
 *        --help prints the usage and exits 0; a bad argument prints "<tool>: error: <what>"
 *        and the usage to stderr and exits 2. Every number must be finite.
 *        Header-only; link Boost::program_options.
 */

#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <boost/program_options.hpp>

#include "jackal_aic/base/json_number.hpp"

namespace jackal_aic
{
/// Exit status of a tool for bad arguments.
constexpr int kExitBadArguments = 2;

/**
 * \brief A tool's command line: long options only (so "-0.5" is a value, not an option),
 *        positional arguments, flags, comma-separated lists, repeatable KEY=VALUE overrides.
 *
 * Usage: declare the options with the member functions (each writes into the variable it is
 * given, whose current value is the default shown by --help), then
 * `if (const int code = cl.parse(argc, argv); code >= 0) return code;`.
 * Checks after parsing report through bad().
 */
class CommandLine
{
public:
  /**
   * \param tool         the tool's name, first word of every error line
   * \param description  one paragraph printed at the top of --help
   */
  CommandLine(std::string tool, std::string description)
    : tool_(std::move(tool)), description_(std::move(description)), options_("Options", 100, 50)
  {
    options_.add_options()("help", "print this help and exit");
  }

  /// Text printed below the options by --help (exit codes, notes).
  void footer(const std::string& text) { footer_ = text; }

  /**
   * \brief An option "--NAME VALUE" writing into *value (its current value is the default).
   * \param required  the option must be given
   * A double given on the command line must be finite (nan and inf are bad arguments).
   */
  template <typename T>
  void option(const std::string& name, T* value, const std::string& help, bool required = false)
  {
    auto* semantic = boost::program_options::value<T>(value);
    if (required)
    {
      semantic->required();
    }
    else
    {
      std::ostringstream os;
      os << *value;
      semantic->default_value(*value, os.str());
    }
    options_.add_options()(name.c_str(), semantic, help.c_str());
    addFiniteCheck(name, value);
  }

  /// A flag "--NAME" (no value): *value becomes true when given.
  void flag(const std::string& name, bool* value, const std::string& help)
  {
    options_.add_options()(name.c_str(), boost::program_options::bool_switch(value), help.c_str());
  }

  /**
   * \brief A list "--NAME A,B,C" (comma-separated; repeating the option appends). Replaces the
   *        default in *values when given. Elements are parsed as T (double: finite).
   */
  template <typename T>
  void list(const std::string& name, std::vector<T>* values, const std::string& help)
  {
    auto texts = std::make_shared<std::vector<std::string>>();
    options_.add_options()(name.c_str(), boost::program_options::value<std::vector<std::string>>(texts.get()),
                           (help + " (comma-separated)").c_str());
    keep_.push_back(texts);
    checks_.push_back([this, name, values, texts]() -> std::string {
      if (!given(name))
      {
        return {};
      }
      values->clear();
      for (const std::string& text : *texts)
      {
        std::stringstream ss(text);
        std::string item;
        while (std::getline(ss, item, ','))
        {
          T v{};
          if (!convert(item, &v))
          {
            return "--" + name + ": '" + item + "' is not a valid value";
          }
          values->push_back(v);
        }
      }
      if (values->empty())
      {
        return "--" + name + ": empty list";
      }
      return {};
    });
  }

  /// "--NAME X1 ... Xn": exactly `count` finite numbers after the option.
  void numbers(const std::string& name, std::vector<double>* values, std::size_t count, const std::string& help)
  {
    options_.add_options()(name.c_str(), boost::program_options::value<std::vector<double>>(values)->multitoken(),
                           help.c_str());
    checks_.push_back([this, name, values, count]() -> std::string {
      if (given(name) && values->size() != count)
      {
        return "--" + name + " takes exactly " + std::to_string(count) + " numbers";
      }
      return {};
    });
    addFiniteCheck(name, values);
  }

  /**
   * \brief A repeatable "--NAME KEY=VALUE" override, one per occurrence; the texts are parsed by
   *        parseOverride() / applyOverrides() (include/jackal_aic/overrides/yaml_overrides.hpp), the one
   *        override parser of the tools.
   */
  void overrides(const std::string& name, std::vector<std::string>* values, const std::string& help)
  {
    addRepeated(name, values, help + " (KEY=VALUE, repeatable)");
  }

  /// A repeatable "--NAME TEXT" (e.g. a file), one value per occurrence, in order.
  void repeated(const std::string& name, std::vector<std::string>* values, const std::string& help)
  {
    addRepeated(name, values, help + " (repeatable)");
  }

  /// A required positional argument (e.g. the configuration file), in order of declaration.
  void positional(const std::string& name, std::string* value, const std::string& help)
  {
    hidden_.add_options()(name.c_str(), boost::program_options::value<std::string>(value)->required(), help.c_str());
    positional_.add(name.c_str(), 1);
    positional_names_.push_back(name);
  }

  /**
   * \brief Parse argv and run the checks.
   * \return -1 to go on; otherwise the exit status for main(): 0 after --help (usage on
   *         stdout), kExitBadArguments after a bad argument (message and usage on stderr)
   */
  int parse(int argc, char** argv)
  {
    namespace po = boost::program_options;
    try
    {
      const int style = po::command_line_style::unix_style ^ po::command_line_style::allow_short;
      po::options_description all;
      all.add(options_).add(hidden_);
      po::store(po::command_line_parser(argc, argv).options(all).positional(positional_).style(style).run(), map_);
      if (map_.count("help") > 0)
      {
        std::cout << usage();
        return 0;
      }
      po::notify(map_);
    }
    catch (const po::required_option& e)
    {
      for (const auto& p : positional_names_)
      {
        if (e.get_option_name() == "--" + p)
        {
          return bad("missing argument " + p);
        }
      }
      return bad(e.what());
    }
    catch (const po::error& e)
    {
      return bad(e.what());
    }
    for (const auto& check : checks_)
    {
      const std::string message = check();
      if (!message.empty())
      {
        return bad(message);
      }
    }
    return -1;
  }

  /// Whether the option was given on the command line (not just defaulted).
  bool given(const std::string& name) const
  {
    const auto it = map_.find(name);
    return it != map_.end() && !it->second.defaulted();
  }

  /**
   * \brief Report a bad argument found after parsing (a value out of its range, a choice that
   *        does not exist): prints "<tool>: error: <message>" and the usage to stderr.
   * \return kExitBadArguments, for main() to return
   */
  int bad(const std::string& message) const
  {
    std::cerr << tool_ << ": error: " << message << "\n" << usage();
    return kExitBadArguments;
  }

  /// The --help text.
  std::string usage() const
  {
    std::ostringstream os;
    os << description_ << "\n\nUsage: " << tool_;
    for (const auto& p : positional_names_)
    {
      os << " " << p;
    }
    os << " [options]\n";
    for (const auto& p : positional_names_)
    {
      const auto* d = hidden_.find_nothrow(p, false);
      os << "  " << p << ": " << (d ? d->description() : "") << "\n";
    }
    os << options_;
    if (!footer_.empty())
    {
      os << "\n" << footer_ << "\n";
    }
    return os.str();
  }

private:
  void addRepeated(const std::string& name, std::vector<std::string>* values, const std::string& help)
  {
    options_.add_options()(name.c_str(), boost::program_options::value<std::vector<std::string>>(values)->composing(),
                           help.c_str());
  }

  static bool convert(const std::string& text, double* v)
  {
    char* end = nullptr;
    *v = std::strtod(text.c_str(), &end);
    return !text.empty() && end != nullptr && *end == '\0' && std::isfinite(*v);
  }
  static bool convert(const std::string& text, std::string* v)
  {
    *v = text;
    return !text.empty();
  }

  template <typename T>
  void addFiniteCheck(const std::string&, T*)
  {
  }
  void addFiniteCheck(const std::string& name, double* value)
  {
    checks_.push_back([this, name, value]() -> std::string {
      return !given(name) || std::isfinite(*value) ?
                 std::string() :
                 "--" + name + ": '" + std::to_string(*value) + "' is not a finite number";
    });
  }
  void addFiniteCheck(const std::string& name, std::vector<double>* values)
  {
    checks_.push_back([this, name, values]() -> std::string {
      for (double v : given(name) ? *values : std::vector<double>())
      {
        if (!std::isfinite(v))
        {
          return "--" + name + ": '" + std::to_string(v) + "' is not a finite number";
        }
      }
      return {};
    });
  }

  std::string tool_;
  std::string description_;
  std::string footer_;
  boost::program_options::options_description options_;
  boost::program_options::options_description hidden_;  ///< the positional arguments
  boost::program_options::positional_options_description positional_;
  std::vector<std::string> positional_names_;
  boost::program_options::variables_map map_;
  std::vector<std::function<std::string()>> checks_;
  std::vector<std::shared_ptr<std::vector<std::string>>> keep_;
};

}  // namespace jackal_aic
