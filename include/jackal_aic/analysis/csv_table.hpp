#pragma once
/**
 * \file csv_table.hpp
 * \brief The CSV reading of the tools (aic_step_metrics, aic_track_metrics, twist profiles):
 *        comma-separated cells, an optional or required header line, '#' comment lines and
 *        empty lines skipped, numbers checked whole. ROS-free, standard library only.
 */

#include <iosfwd>
#include <string>
#include <vector>

namespace jackal_aic
{
namespace analysis
{
/// Whether a CSV file starts with a header line naming its columns.
enum class CsvHeader
{
  kRequired,  ///< the first non-comment line is the header
  kOptional   ///< the first non-comment line is a header if its first cell is not a number
};

/// A CSV file as text cells.
struct CsvTable
{
  std::string source;                          ///< file name, for messages
  std::vector<std::string> header;             ///< column names (empty: no header)
  int header_line = 0;                         ///< line number of the header (0: none)
  std::vector<std::vector<std::string>> rows;  ///< data rows, cells trimmed of blanks and quotes
  std::vector<int> lines;                      ///< 1-based line number of each row in the file

  /// Index of the column named `name` in the header, or -1.
  int column(const std::string& name) const;

  /// "<source> line N: " for row `row`, the prefix of every message about it.
  std::string where(std::size_t row) const;

  /**
   * \brief The cell (row, col) as a finite number.
   * \param label  what the cell is, for the message (e.g. the column's name)
   * \throws std::invalid_argument "<source> line N: <label> '<cell>' is not a number" (or
   *         "... is not finite" for nan / inf), also when the row has no such cell
   */
  double number(std::size_t row, int col, const std::string& label) const;
};

/// Cells of one CSV line, each trimmed of blanks and double quotes; a trailing comma gives an
/// empty last cell.
std::vector<std::string> splitCsvLine(const std::string& line);

/// `cell` as a double if the whole of it is one (strtod; "nan" and "inf" parse, to NaN and Inf).
bool parseCsvNumber(const std::string& cell, double* out);

/**
 * \brief Reads a CSV text.
 * \param in      the text
 * \param source  name used in messages
 * \param header  whether a header line is required or optional
 * \throws std::invalid_argument "<source> has no header line" when a header is required and the
 *         text has no non-comment line
 */
CsvTable readCsv(std::istream& in, const std::string& source, CsvHeader header);

}  // namespace analysis
}  // namespace jackal_aic
