#include "app/report_csv.hpp"

#include <charconv>
#include <fstream>
#include <sstream>
#include <string_view>

#include "core/errors.hpp"

namespace fl::report {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      out.push_back(trim(line.substr(start)));
      return out;
    }
    out.push_back(trim(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

std::string shown(std::string_view s) {
  std::string o(s.substr(0, 40));
  if (s.size() > 40) o += "...";
  return o;
}

}  // namespace

int CsvTable::index(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

const std::vector<double>& CsvTable::column(const std::string& name) const {
  const int i = index(name);
  if (i < 0) throw InputError(path + ":1: no column '" + name + "' in the header");
  return columns[static_cast<std::size_t>(i)];
}

CsvTable parseCsv(const std::string& text, const std::string& path, const std::vector<std::string>& required) {
  CsvTable t;
  t.path = path;
  std::size_t pos = 0;
  long lineNo = 0;
  bool haveHeader = false;
  while (pos < text.size()) {
    const std::size_t nl = text.find('\n', pos);
    const bool complete = nl != std::string::npos;
    const std::string_view line(text.data() + pos, (complete ? nl : text.size()) - pos);
    pos = complete ? nl + 1 : text.size();
    ++lineNo;
    if (trim(line).empty()) continue;
    const std::string where = path + ":" + std::to_string(lineNo);
    if (!haveHeader) {
      for (std::string_view f : split(line)) {
        if (f.empty()) throw InputError(where + ": empty column name in the header");
        t.header.emplace_back(f);
      }
      t.columns.resize(t.header.size());
      haveHeader = true;
      continue;
    }
    if (!complete) {  // a run writes whole lines: one without its newline is unfinished
      t.droppedPartialLine = true;
      break;
    }
    const std::vector<std::string_view> fields = split(line);
    if (fields.size() != t.header.size())
      throw InputError(where + ": " + std::to_string(fields.size()) + " fields, but the header has " +
                       std::to_string(t.header.size()));
    for (std::size_t c = 0; c < fields.size(); ++c) {
      const std::string_view f = fields[c];
      double v = 0;
      const auto res = std::from_chars(f.data(), f.data() + f.size(), v);
      if (f.empty() || res.ec != std::errc() || res.ptr != f.data() + f.size())
        throw InputError(where + ": column " + std::to_string(c + 1) + " ('" + t.header[c] +
                         "'): expected a number, got '" + shown(f) + "'");
      t.columns[c].push_back(v);
    }
  }
  if (!haveHeader) throw InputError(path + ":1: empty file, expected a header line of column names");
  for (const std::string& r : required)
    if (t.index(r) < 0) throw InputError(path + ":1: the header has no column '" + r + "'");
  return t;
}

CsvTable readCsv(const std::string& path, const std::vector<std::string>& required) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw IoError(path + ": read error");
  return parseCsv(s.str(), path, required);
}

}  // namespace fl::report
