#include "output/CsvSeries.hpp"

#include <fstream>
#include <stdexcept>

#include "io/AtomicFile.hpp"
#include "io/RoundTripNumber.hpp"

namespace tlsph {

CsvSeries::CsvSeries(std::filesystem::path file, std::vector<std::string> columns)
    : file_(std::move(file)), columns_(std::move(columns)) {
  if (columns_.empty())
    throw std::invalid_argument("CSV series " + file_.string() + " has no columns");
  for (const auto& name : columns_)
    if (name.empty() || name.front() == '#' || name.find_first_of(",\"\n\r") != std::string::npos)
      throw std::invalid_argument("CSV column name '" + name + "' in " + file_.string() +
                                  " is empty or holds a comma, quote, line break or leading #");
}

void CsvSeries::setPreamble(std::vector<std::string> lines) {
  preamble_ = std::move(lines);
}

void CsvSeries::append(const std::vector<double>& row) {
  if (row.size() != columns_.size())
    throw std::invalid_argument("CSV row of " + std::to_string(row.size()) + " values for " +
                                std::to_string(columns_.size()) + " columns in " + file_.string());
  for (std::size_t c = 0; c < row.size(); ++c) {
    if (c > 0) rows_ += ',';
    rows_ += roundTripText(row[c]);
  }
  rows_ += '\n';
  ++rowCount_;
}

void CsvSeries::resume(std::size_t rows) {
  std::ifstream in(file_, std::ios::binary);
  if (!in)
    throw std::runtime_error("cannot continue CSV series " + file_.string() +
                             ": the file is missing or unreadable");
  std::string header;
  for (std::size_t c = 0; c < columns_.size(); ++c)
    header += (c > 0 ? "," : "") + columns_[c];
  std::string head, kept, line;
  bool headerSeen = false;
  std::size_t count = 0;
  while (count < rows && std::getline(in, line)) {
    if (!headerSeen) {
      if (!line.empty() && line[0] == '#') {
        head += line + '\n';
        continue;
      }
      if (line != header)
        throw std::runtime_error("cannot continue CSV series " + file_.string() +
                                 ": its header is '" + line + "', this run writes '" + header +
                                 "'");
      headerSeen = true;
      continue;
    }
    kept += line + '\n';
    ++count;
  }
  if (!headerSeen && rows == 0) {
    // Nothing to keep: a fresh file with this run's preamble.
    rows_.clear();
    rowCount_ = 0;
    return;
  }
  if (count < rows)
    throw std::runtime_error("cannot continue CSV series " + file_.string() + ": it holds " +
                             std::to_string(count) + " rows, the checkpoint expects " +
                             std::to_string(rows));
  resumedHead_ = head;
  rows_ = kept;
  rowCount_ = count;
}

void CsvSeries::flush() {
  std::string head = resumedHead_;
  if (head.empty())
    for (const auto& line : preamble_) {
      head += "# ";
      for (const char c : line) {
        if (c == '\r') continue;
        head += c;
        if (c == '\n') head += "# ";
      }
      head += '\n';
    }
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    if (c > 0) head += ',';
    head += columns_[c];
  }
  head += '\n';

  writeTextAtomically(file_, {head, rows_}, "CSV");
}

}  // namespace tlsph
