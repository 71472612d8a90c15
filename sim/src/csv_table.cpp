#include "jackal_sim/csv_table.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace sim
{
namespace
{
std::string trimCell(const std::string& s)
{
  const auto b = s.find_first_not_of(" \t\r\"");
  const auto e = s.find_last_not_of(" \t\r\"");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

std::vector<std::string> cells(const std::string& line)
{
  std::vector<std::string> out;
  std::size_t begin = 0;
  for (;;)
  {
    const std::size_t comma = line.find(',', begin);
    out.push_back(trimCell(line.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin)));
    if (comma == std::string::npos)
    {
      return out;
    }
    begin = comma + 1;
  }
}
}  // namespace

std::size_t CsvTable::column(const std::string& name) const
{
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    if (names[i] == name)
    {
      return i;
    }
  }
  std::string list;
  for (const std::string& n : names)
  {
    list += (list.empty() ? "" : ", ") + n;
  }
  throw std::invalid_argument(source + ": no column '" + name + "' (columns: " + list + ")");
}

std::vector<double> CsvTable::values(const std::string& name) const
{
  const std::size_t c = column(name);
  std::vector<double> out;
  out.reserve(rows.size());
  for (const auto& r : rows)
  {
    out.push_back(r[c]);
  }
  return out;
}

CsvTable readCsvTable(std::istream& in, const std::string& source)
{
  CsvTable t;
  t.source = source;
  std::string line;
  int number = 0;
  bool header = false;
  while (std::getline(in, line))
  {
    ++number;
    const std::string where = source + ":" + std::to_string(number);
    const std::string trimmed = trimCell(line);
    if (trimmed.empty() || trimmed[0] == '#')
    {
      continue;
    }
    const std::vector<std::string> c = cells(line);
    if (!header)
    {
      std::set<std::string> seen;
      for (const std::string& n : c)
      {
        if (n.empty() || !seen.insert(n).second)
        {
          throw std::invalid_argument(where + ": header has an empty or duplicate column name '" + n + "'");
        }
      }
      t.names = c;
      header = true;
      continue;
    }
    if (c.size() != t.names.size())
    {
      throw std::invalid_argument(where + ": " + std::to_string(c.size()) + " cells, the header names " +
                                  std::to_string(t.names.size()));
    }
    std::vector<double> row;
    for (std::size_t i = 0; i < c.size(); ++i)
    {
      char* end = nullptr;
      const double v = std::strtod(c[i].c_str(), &end);
      if (c[i].empty() || end == nullptr || *end != '\0' || !std::isfinite(v))
      {
        throw std::invalid_argument(where + ": column '" + t.names[i] + "' is not a finite number ('" + c[i] + "')");
      }
      row.push_back(v);
    }
    t.rows.push_back(row);
  }
  if (!header)
  {
    throw std::invalid_argument(source + ": no header line");
  }
  if (t.rows.empty())
  {
    throw std::invalid_argument(source + ": no data rows");
  }
  return t;
}

CsvTable readCsvFile(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
  {
    throw std::invalid_argument(path + ": cannot be opened");
  }
  return readCsvTable(in, path);
}

}  // namespace sim
}  // namespace jackal_aic
