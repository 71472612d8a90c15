#pragma once
/**
 * \file csv_table.hpp
 * \brief A numeric CSV table with a header line (the input of plant_replay: a /cmd_drive stream
 *        or a twist profile). ROS-free.
 *
 * Format: the first line that is neither empty nor a comment ('#') names the columns
 * (comma-separated, surrounding spaces and quotes ignored); every further such line is one row
 * of finite numbers, as many as there are names.
 */

#include <cstddef>
#include <istream>
#include <string>
#include <vector>

namespace jackal_aic
{
namespace sim
{
/// Columns by name, rows of finite numbers.
struct CsvTable
{
  std::string source;                     ///< file name used in error messages
  std::vector<std::string> names;         ///< column names, in file order
  std::vector<std::vector<double>> rows;  ///< each of names.size() finite numbers

  /// Index of the column `name`.
  /// \throws std::invalid_argument "<source>: no column '<name>' (columns: ...)"
  std::size_t column(const std::string& name) const;
  /// The values of column `name`, one per row. \throws as column()
  std::vector<double> values(const std::string& name) const;
};

/**
 * \brief Read a CsvTable.
 * \param in     the text
 * \param source name for error messages (e.g. the file path)
 * \throws std::invalid_argument naming the source and the line on a missing header, a duplicate
 *         or empty column name, a row with another number of cells, or a cell that is not a
 *         finite number; and when there is no row
 */
CsvTable readCsvTable(std::istream& in, const std::string& source);

/// readCsvTable() of a file. \throws std::invalid_argument also when the file cannot be opened
CsvTable readCsvFile(const std::string& path);

}  // namespace sim
}  // namespace jackal_aic
