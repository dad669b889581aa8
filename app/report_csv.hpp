/*
 * A small reader for the numeric CSV files a run writes (timeseries.csv, cycles.csv): a header line of
 * column names, then rows of numbers. Used by the report generator (fabriclab-report).
 * Robust to the way runs write: records are flushed line by line, so a killed or still-running run may end
 * in an unfinished line without its newline; that line is dropped (and flagged), never misread.
 * Anything else that is not a number, or a row with the wrong number of fields, is an InputError naming
 * "<file>:<line>: column <n> ('<name>')". A file that cannot be opened is an IoError naming it.
 * No Qt, no VTK.
 */
#pragma once

#include <string>
#include <vector>

namespace fl::report {

struct CsvTable {
  std::string path;
  std::vector<std::string> header;
  std::vector<std::vector<double>> columns;  // column-major: columns[c][row]
  bool droppedPartialLine = false;           // an unfinished last line (no newline) was ignored

  std::size_t rows() const { return columns.empty() ? 0 : columns[0].size(); }
  int index(const std::string& name) const;  // -1 if absent
  bool has(const std::string& name) const { return index(name) >= 0; }
  // The column's values; throws InputError naming the file if the column does not exist.
  const std::vector<double>& column(const std::string& name) const;
};

// Reads a CSV file of numbers; `required` columns must be in the header (InputError naming file and line
// 1 otherwise). Blank lines are skipped; '\r' line ends are accepted.
CsvTable readCsv(const std::string& path, const std::vector<std::string>& required = {});

// The same from text already in memory (`path` only names it in messages).
CsvTable parseCsv(const std::string& text, const std::string& path, const std::vector<std::string>& required = {});

}  // namespace fl::report
