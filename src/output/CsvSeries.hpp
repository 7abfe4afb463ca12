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

  // Continues the series of an interrupted run from its file: keeps the file's comment lines and
  // its first `rows` rows (those before the checkpoint; later ones are dropped, so the restarted
  // run appends without duplicates or gaps). Throws std::runtime_error naming the file if it is
  // missing, its header differs from the columns, or it holds fewer rows.
  void resume(std::size_t rows);

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
  std::string resumedHead_;  // comment lines read back by resume(), written instead of preamble_
  std::string rows_;         // formatted once on append, so repeated flushes only copy text
  std::size_t rowCount_ = 0;
};

}  // namespace tlsph
