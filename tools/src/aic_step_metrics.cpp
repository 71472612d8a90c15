/**
 * \file aic_step_metrics.cpp
 * \brief CLI: step-response metrics (jackal_aic::analysis::computeStepMetrics) of one column of a CSV file,
 *        printed as one JSON line. The experiment scripts call this so that the metrics have one
 *        implementation.
 *
 * Usage: aic_step_metrics FILE.csv --step-time T --initial Y0 --target Y1
 *            [--time-column time] [--value-column value] [--end-time T_END]
 *            [--band-basis final|step] [--settling-band 0.05] [--window 0.5]
 * FILE "-" reads standard input. The CSV has a header line naming the columns; lines starting
 * with '#' and empty lines are skipped. Command line on Boost.program_options (tools/include/jackal_tools/cli.hpp).
 * Exit 0 on success, 1 on bad data, 2 on bad arguments.
 */
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "jackal_tools/cli.hpp"
#include "jackal_aic/analysis/csv_table.hpp"
#include "jackal_aic/analysis/step_metrics.hpp"

namespace
{
[[noreturn]] void fail(int code, const std::string& msg)
{
  std::cerr << "aic_step_metrics: error: " << msg << "\n";
  std::exit(code);
}
}  // namespace

int main(int argc, char** argv)
{
  std::string file;
  std::string time_column = "time";
  std::string value_column = "value";
  std::string band_basis = "final";
  jackal_aic::analysis::StepMetricsOptions o;
  jackal_aic::CommandLine cl("aic_step_metrics", "Step-response metrics of one column of a CSV file, printed as one "
                                                 "JSON line: rise_time, settling_time [s from "
                                                 "the step], overshoot_percent [% of step], steady_state_error [target "
                                                 "- value, time-weighted mean over the last "
                                                 "WINDOW s]. The final value of the settling band is the set point "
                                                 "TARGET.");
  cl.positional("FILE", &file, "CSV with a header line naming the columns; '-' reads stdin");
  cl.option("step-time", &o.step_time, "time of the set-point step [s]", true);
  cl.option("initial", &o.initial, "value before the step", true);
  cl.option("target", &o.target, "set point after the step", true);
  cl.option("time-column", &time_column, "name of the time column");
  cl.option("value-column", &value_column, "name of the value column");
  cl.option("end-time", &o.end_time, "ignore samples after this time [s]");
  cl.option("band-basis", &band_basis, "settling band relative to the final value or the step size: final|step");
  cl.option("settling-band", &o.settling_band, "settling band [fraction]");
  cl.option("window", &o.steady_state_window, "steady-state window [s]");
  cl.footer("Lines starting with '#' and empty lines are skipped. Exit 0 on success, 1 on bad data, 2 on bad "
            "arguments.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  if (band_basis == "final")
  {
    o.band_basis = jackal_aic::analysis::SettlingBandBasis::kFinalValue;
  }
  else if (band_basis == "step")
  {
    o.band_basis = jackal_aic::analysis::SettlingBandBasis::kStepSize;
  }
  else
  {
    return cl.bad("--band-basis '" + band_basis + "' (allowed: final, step)");
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
  std::vector<double> t;
  std::vector<double> v;
  try
  {
    const jackal_aic::analysis::CsvTable csv =
        jackal_aic::analysis::readCsv(*in, "'" + file + "'", jackal_aic::analysis::CsvHeader::kRequired);
    const int tcol = csv.column(time_column);
    const int vcol = csv.column(value_column);
    if (tcol < 0 || vcol < 0)
    {
      std::string names;
      for (const auto& h : csv.header)
      {
        names += (names.empty() ? "" : ", ") + h;
      }
      fail(1, "column '" + (tcol < 0 ? time_column : value_column) + "' not in the header (" + names + ")");
    }
    for (std::size_t r = 0; r < csv.rows.size(); ++r)
    {
      t.push_back(csv.number(r, tcol, time_column));
      v.push_back(csv.number(r, vcol, value_column));
    }
  }
  catch (const std::invalid_argument& e)
  {
    fail(1, e.what());
  }
  try
  {
    const auto m = jackal_aic::analysis::computeStepMetrics(t, v, o);
    std::cout << jackal_aic::analysis::toJson(m, o) << std::endl;
  }
  catch (const std::invalid_argument& e)
  {
    fail(1, std::string(e.what()) + " (file '" + file + "')");
  }
  return 0;
}
