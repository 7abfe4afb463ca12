// Files appear whole or not at all: written under a temporary name, then renamed.
#pragma once

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string>
#include <string_view>

namespace tlsph {

// Calls write(temporary) to produce the file, then renames it onto `target` (atomic on
// POSIX within one file system). If write throws, the temporary is removed and the
// target is left as it was. Creates the parent directory if needed.
void writeAtomically(const std::filesystem::path& target,
                     const std::function<void(const std::filesystem::path&)>& write);

// A text file of these parts, in order, written atomically. Throws std::runtime_error
// "cannot write <kind> file <target>[: reason]" if it cannot be written.
void writeTextAtomically(const std::filesystem::path& target,
                         std::initializer_list<std::string_view> parts, const std::string& kind);

}  // namespace tlsph
