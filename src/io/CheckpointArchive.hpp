// The container of a checkpoint file: named blocks of bytes behind a magic line and a format
// number, closed by a checksum, so that a foreign, truncated or damaged file is refused with
// a message instead of being half read. Numbers are stored in the machine's own byte order
// (a checkpoint continues a run on the machine that wrote it; the header records the order).
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace tlsph {

// A checkpoint that cannot be read or does not fit the run; the message says why.
class CheckpointError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

class CheckpointWriter {
 public:
  void putBytes(const std::string& name, const void* data, std::size_t size);
  void putString(const std::string& name, const std::string& text) {
    putBytes(name, text.data(), text.size());
  }
  template <class T>
  void put(const std::string& name, const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    putBytes(name, &value, sizeof(T));
  }
  // T: plain data (numbers; fixed-size Eigen vectors and matrices, which are arrays of doubles).
  template <class T>
  void putVector(const std::string& name, const std::vector<T>& values) {
    static_assert(std::is_trivially_destructible_v<T>);
    putBytes(name, values.data(), values.size() * sizeof(T));
  }
  // Writes the file atomically (temporary name, then rename). Throws CheckpointError naming
  // the file when it cannot be written.
  void write(const std::filesystem::path& file) const;

 private:
  std::vector<std::pair<std::string, std::string>> blocks_;
};

class CheckpointReader {
 public:
  // Reads and verifies the whole file; throws CheckpointError naming it if it is missing,
  // not a tlsph checkpoint, of another format, truncated or damaged.
  explicit CheckpointReader(const std::filesystem::path& file);

  bool has(const std::string& name) const { return blocks_.count(name) > 0; }
  const std::string& bytes(const std::string& name) const;
  std::string getString(const std::string& name) const { return bytes(name); }
  template <class T>
  T get(const std::string& name) const {
    static_assert(std::is_trivially_copyable_v<T>);
    const std::string& b = bytes(name);
    if (b.size() != sizeof(T)) throw damaged(name);
    T value;
    std::memcpy(&value, b.data(), sizeof(T));
    return value;
  }
  template <class T>
  std::vector<T> getVector(const std::string& name) const {
    static_assert(std::is_trivially_destructible_v<T>);
    const std::string& b = bytes(name);
    if (b.size() % sizeof(T) != 0) throw damaged(name);
    std::vector<T> values(b.size() / sizeof(T));
    if (!values.empty()) std::memcpy(static_cast<void*>(values.data()), b.data(), b.size());
    return values;
  }
  const std::filesystem::path& file() const { return file_; }

 private:
  CheckpointError damaged(const std::string& block) const;
  std::filesystem::path file_;
  std::map<std::string, std::string> blocks_;
};

}  // namespace tlsph
