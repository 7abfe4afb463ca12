// A time-series table (energies, probes) kept in memory and written as CSV: each flush
// rewrites the whole file atomically, so the file on disk is always complete.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace tlsph {

class CsvSeries {
 public:
  // Nothing is written until flush(). Throws std::invalid_argument if there are no columns or
  // a name is empty or holds ',', '"', '#' at its start, or a line break (no quoting is done,
  // so that plain split-on-comma readers work).
  CsvSeries(std::filesystem::path file, std::vector<std::string> columns);

  // Comment lines written as "# line" above the header (command, units). Embedded line breaks
  // start new comment lines.
  void setPreamble(std::vector<std::string> lines);

  // Throws std::invalid_argument if row.size() != column count.
  void append(const std::vector<double>& row);

  // (Re)writes preamble, header and all rows so far; numbers in shortest round-trip form.
  // Throws std::runtime_error naming the file on failure.
  void flush();

  std::size_t rowCount() const { return rowCount_; }
  const std::filesystem::path& path() const { return file_; }
  const std::vector<std::string>& columns() const { return columns_; }

 private:
  std::filesystem::path file_;
  std::vector<std::string> columns_;
  std::vector<std::string> preamble_;
  std::string rows_;  // formatted once on append, so repeated flushes only copy text
  std::size_t rowCount_ = 0;
};

}  // namespace tlsph
