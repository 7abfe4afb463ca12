#include "io/CheckpointArchive.hpp"

#include <cerrno>
#include <fstream>
#include <iterator>

#include "io/AtomicFile.hpp"

namespace tlsph {

namespace {

constexpr char kMagic[] = "tlsph checkpoint\n";
constexpr std::uint32_t kFormat = 1;
constexpr std::uint32_t kByteOrderMark = 0x01020304u;

// FNV-1a, 64 bit: catches truncation and damage, not tampering.
std::uint64_t checksum(const std::string& data) {
  std::uint64_t h = 1469598103934665603ull;
  for (const unsigned char c : data) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

template <class T>
void append(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

}  // namespace

void CheckpointWriter::putBytes(const std::string& name, const void* data, std::size_t size) {
  blocks_.emplace_back(name, std::string(static_cast<const char*>(data), size));
}

void CheckpointWriter::write(const std::filesystem::path& file) const {
  std::string body;
  append(body, kFormat);
  append(body, kByteOrderMark);
  append(body, static_cast<std::uint64_t>(blocks_.size()));
  for (const auto& [name, bytes] : blocks_) {
    append(body, static_cast<std::uint64_t>(name.size()));
    body += name;
    append(body, static_cast<std::uint64_t>(bytes.size()));
    body += bytes;
  }
  const std::uint64_t sum = checksum(body);
  try {
    writeAtomically(file, [&](const std::filesystem::path& temporary) {
      std::ofstream out(temporary, std::ios::binary);
      out.write(kMagic, sizeof kMagic - 1);
      out.write(body.data(), static_cast<std::streamsize>(body.size()));
      out.write(reinterpret_cast<const char*>(&sum), sizeof sum);
      out.close();
      if (!out)
        throw CheckpointError("cannot write checkpoint " + file.string() + ": " +
                              std::strerror(errno ? errno : EIO));
    });
  } catch (const std::filesystem::filesystem_error& e) {
    throw CheckpointError("cannot write checkpoint " + file.string() + ": " + e.what());
  }
}

CheckpointReader::CheckpointReader(const std::filesystem::path& file) : file_(file) {
  const std::string where = "checkpoint " + file.string() + ": ";
  std::error_code status;
  if (!std::filesystem::is_regular_file(file, status))
    throw CheckpointError(
        where + (std::filesystem::exists(file, status) ? "is not a regular file" : "no such file"));
  std::ifstream in(file, std::ios::binary);
  if (!in) throw CheckpointError(where + "cannot open: " + std::strerror(errno));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t magic = sizeof kMagic - 1;
  if (text.compare(0, magic, kMagic) != 0)
    throw CheckpointError(where + "not a tlsph checkpoint (it does not start with '" +
                          std::string(kMagic, magic - 1) + "')");
  if (text.size() < magic + 2 * sizeof(std::uint32_t) + 2 * sizeof(std::uint64_t))
    throw CheckpointError(where + "truncated (" + std::to_string(text.size()) + " bytes)");
  const std::string body = text.substr(magic, text.size() - magic - sizeof(std::uint64_t));
  std::size_t at = 0;
  auto take = [&](auto& value) {
    if (at + sizeof value > body.size())
      throw CheckpointError(where + "truncated (" + std::to_string(text.size()) + " bytes)");
    std::memcpy(&value, body.data() + at, sizeof value);
    at += sizeof value;
  };
  std::uint32_t format = 0, order = 0;
  take(format);
  take(order);
  if (order != kByteOrderMark)
    throw CheckpointError(where + "written on a machine of another byte order");
  if (format != kFormat)
    throw CheckpointError(where + "checkpoint format " + std::to_string(format) +
                          ", this tlsph reads format " + std::to_string(kFormat));
  std::uint64_t stored = 0;
  std::memcpy(&stored, text.data() + text.size() - sizeof stored, sizeof stored);
  if (stored != checksum(body))
    throw CheckpointError(where + "damaged or truncated (checksum mismatch)");
  std::uint64_t count = 0;
  take(count);
  for (std::uint64_t b = 0; b < count; ++b) {
    std::uint64_t length = 0;
    take(length);
    if (length > body.size() - at) throw CheckpointError(where + "damaged block table");
    std::string name = body.substr(at, length);
    at += length;
    take(length);
    if (length > body.size() - at) throw CheckpointError(where + "damaged block '" + name + "'");
    blocks_[name] = body.substr(at, length);
    at += length;
  }
}

const std::string& CheckpointReader::bytes(const std::string& name) const {
  const auto b = blocks_.find(name);
  if (b == blocks_.end())
    throw CheckpointError("checkpoint " + file_.string() + ": has no '" + name +
                          "' (written by another version of tlsph?)");
  return b->second;
}

CheckpointError CheckpointReader::damaged(const std::string& block) const {
  return CheckpointError("checkpoint " + file_.string() + ": block '" + block +
                         "' has the wrong size (damaged, or written by another version)");
}

}  // namespace tlsph
