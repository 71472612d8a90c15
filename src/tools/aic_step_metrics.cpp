/**
 * \file aic_step_metrics.cpp
 * \brief CLI: step-response metrics (jackal_aic::computeStepMetrics) of one column of a CSV file,
 *        printed as one JSON line. The experiment scripts call this so that the metrics have one
 *        implementation.
 *
 * Usage: aic_step_metrics FILE.csv --step-time T --initial Y0 --target Y1
 *            [--time-column time] [--value-column value] [--end-time T_END]
 *            [--band-basis final|step] [--settling-band 0.05] [--window 0.5]
 * FILE "-" reads standard input. The CSV has a header line naming the columns; lines starting
 * with '#' and empty lines are skipped. Exit 0 on success, 1 on bad data, 2 on bad arguments.
 */
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "jackal_aic/step_metrics.hpp"

namespace
{
const char* kUsage =
    "usage: aic_step_metrics FILE.csv --step-time T --initial Y0 --target Y1\n"
    "         [--time-column NAME (default time)] [--value-column NAME (default value)]\n"
    "         [--end-time T_END] [--band-basis final|step (default final)]\n"
    "         [--settling-band FRACTION (default 0.05)] [--window SECONDS (default 0.5)]\n"
    "FILE '-' reads stdin. Prints one JSON line: rise_time, settling_time [s from the step],\n"
    "overshoot_percent [% of step], steady_state_error [target - value, time-weighted mean over\n"
    "the last WINDOW s]. The final value of the settling band is the set point TARGET.\n";

std::string trim(const std::string& s)
{
  const auto b = s.find_first_not_of(" \t\r\"");
  const auto e = s.find_last_not_of(" \t\r\"");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

std::vector<std::string> splitCsv(const std::string& line)
{
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ','))
  {
    out.push_back(trim(cell));
  }
  if (!line.empty() && line.back() == ',')
  {
    out.emplace_back();
  }
  return out;
}

bool parseDouble(const std::string& s, double* out)
{
  if (s.empty())
  {
    return false;
  }
  char* end = nullptr;
  *out = std::strtod(s.c_str(), &end);
  return end != nullptr && *end == '\0';
}

[[noreturn]] void fail(int code, const std::string& msg)
{
  std::cerr << "aic_step_metrics: error: " << msg << "\n";
  if (code == 2)
  {
    std::cerr << kUsage;
  }
  std::exit(code);
}
}  // namespace

int main(int argc, char** argv)
{
  std::string file;
  std::map<std::string, std::string> opts{ { "--time-column", "time" }, { "--value-column", "value" } };
  const std::vector<std::string> known{ "--step-time", "--initial",     "--target",       "--time-column",
                                        "--value-column", "--end-time", "--band-basis", "--settling-band",
                                        "--window" };
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help")
    {
      std::cout << kUsage;
      return 0;
    }
    if (a.rfind("--", 0) == 0)
    {
      bool ok = false;
      for (const auto& k : known)
      {
        ok = ok || k == a;
      }
      if (!ok)
      {
        fail(2, "unknown option " + a);
      }
      if (i + 1 >= argc)
      {
        fail(2, "option " + a + " needs a value");
      }
      opts[a] = argv[++i];
    }
    else if (file.empty())
    {
      file = a;
    }
    else
    {
      fail(2, "more than one input file (" + file + ", " + a + ")");
    }
  }
  if (file.empty())
  {
    fail(2, "no input file");
  }
  jackal_aic::StepMetricsOptions o;
  auto number = [&](const std::string& key, double* out, bool required) {
    const auto it = opts.find(key);
    if (it == opts.end())
    {
      if (required)
      {
        fail(2, "missing " + key);
      }
      return;
    }
    if (!parseDouble(it->second, out) || !std::isfinite(*out))
    {
      fail(2, key + " '" + it->second + "' is not a finite number");
    }
  };
  number("--step-time", &o.step_time, true);
  number("--initial", &o.initial, true);
  number("--target", &o.target, true);
  number("--end-time", &o.end_time, false);
  number("--settling-band", &o.settling_band, false);
  number("--window", &o.steady_state_window, false);
  if (opts.count("--band-basis"))
  {
    const std::string& b = opts["--band-basis"];
    if (b == "final")
    {
      o.band_basis = jackal_aic::SettlingBandBasis::kFinalValue;
    }
    else if (b == "step")
    {
      o.band_basis = jackal_aic::SettlingBandBasis::kStepSize;
    }
    else
    {
      fail(2, "--band-basis '" + b + "' (allowed: final, step)");
    }
  }

  std::ifstream fin;
  std::istream* in = &std::cin;
  if (file != "-")
  {
    fin.open(file);
    if (!fin)
    {
      fail(1, "cannot open '" + file + "'");
    }
    in = &fin;
  }
  std::string line;
  std::vector<std::string> header;
  int line_no = 0;
  while (std::getline(*in, line))
  {
    ++line_no;
    if (!trim(line).empty() && trim(line)[0] != '#')
    {
      header = splitCsv(line);
      break;
    }
  }
  if (header.empty())
  {
    fail(1, "'" + file + "' has no header line");
  }
  int tcol = -1;
  int vcol = -1;
  for (std::size_t c = 0; c < header.size(); ++c)
  {
    if (header[c] == opts["--time-column"])
    {
      tcol = static_cast<int>(c);
    }
    if (header[c] == opts["--value-column"])
    {
      vcol = static_cast<int>(c);
    }
  }
  if (tcol < 0 || vcol < 0)
  {
    std::string names;
    for (const auto& h : header)
    {
      names += (names.empty() ? "" : ", ") + h;
    }
    fail(1, "column '" + (tcol < 0 ? opts["--time-column"] : opts["--value-column"]) + "' not in the header (" +
                names + ")");
  }
  std::vector<double> t;
  std::vector<double> v;
  while (std::getline(*in, line))
  {
    ++line_no;
    if (trim(line).empty() || trim(line)[0] == '#')
    {
      continue;
    }
    const auto cells = splitCsv(line);
    double tv = 0.0;
    double vv = 0.0;
    if (static_cast<int>(cells.size()) <= std::max(tcol, vcol) || !parseDouble(cells[tcol], &tv) ||
        !parseDouble(cells[vcol], &vv))
    {
      fail(1, "line " + std::to_string(line_no) + ": cannot read columns '" + opts["--time-column"] + "' and '" +
                  opts["--value-column"] + "' as numbers: " + line);
    }
    t.push_back(tv);
    v.push_back(vv);
  }
  try
  {
    const auto m = jackal_aic::computeStepMetrics(t, v, o);
    std::cout << jackal_aic::toJson(m, o) << std::endl;
  }
  catch (const std::invalid_argument& e)
  {
    fail(1, std::string(e.what()) + " (file '" + file + "')");
  }
  return 0;
}
