/**
 * \file csv_table.cpp
 * \brief CSV reading of the tools (include/jackal_aic/analysis/csv_table.hpp).
 */
#include "jackal_aic/analysis/csv_table.hpp"

#include <cmath>
#include <cstdlib>
#include <istream>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace analysis
{
namespace
{
std::string trim(const std::string& s)
{
  const auto b = s.find_first_not_of(" \t\r\"");
  const auto e = s.find_last_not_of(" \t\r\"");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}
}  // namespace

std::vector<std::string> splitCsvLine(const std::string& line)
{
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ','))
  {
    out.push_back(trim(cell));
  }
  const std::string t = trim(line);
  if (!t.empty() && t.back() == ',')
  {
    out.emplace_back();
  }
  return out;
}

bool parseCsvNumber(const std::string& cell, double* out)
{
  if (cell.empty())
  {
    return false;
  }
  char* end = nullptr;
  *out = std::strtod(cell.c_str(), &end);
  return end != nullptr && *end == '\0';
}

int CsvTable::column(const std::string& name) const
{
  for (std::size_t i = 0; i < header.size(); ++i)
  {
    if (header[i] == name)
    {
      return static_cast<int>(i);
    }
  }
  return -1;
}

std::string CsvTable::where(std::size_t row) const
{
  return source + " line " + std::to_string(row < lines.size() ? lines[row] : 0) + ": ";
}

double CsvTable::number(std::size_t row, int col, const std::string& label) const
{
  const auto& r = rows.at(row);
  if (col < 0 || static_cast<std::size_t>(col) >= r.size())
  {
    throw std::invalid_argument(where(row) + "no cell for " + label);
  }
  double v = 0.0;
  const std::string& cell = r[static_cast<std::size_t>(col)];
  if (!parseCsvNumber(cell, &v))
  {
    throw std::invalid_argument(where(row) + label + " '" + cell + "' is not a number");
  }
  if (!std::isfinite(v))
  {
    throw std::invalid_argument(where(row) + label + " '" + cell + "' is not finite");
  }
  return v;
}

CsvTable readCsv(std::istream& in, const std::string& source, CsvHeader header)
{
  CsvTable table;
  table.source = source;
  std::string line;
  int line_no = 0;
  bool first = true;
  while (std::getline(in, line))
  {
    ++line_no;
    const std::string text = trim(line);
    if (text.empty() || text[0] == '#')
    {
      continue;
    }
    std::vector<std::string> cells = splitCsvLine(line);
    double unused = 0.0;
    if (first && (header == CsvHeader::kRequired || !parseCsvNumber(cells.front(), &unused)))
    {
      table.header = std::move(cells);
      table.header_line = line_no;
    }
    else
    {
      table.rows.push_back(std::move(cells));
      table.lines.push_back(line_no);
    }
    first = false;
  }
  if (header == CsvHeader::kRequired && table.header.empty())
  {
    throw std::invalid_argument(source + " has no header line");
  }
  return table;
}

}  // namespace analysis
}  // namespace jackal_aic
