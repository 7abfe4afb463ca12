// An error in a scene file or on the command line, located by file, section and key.
#pragma once

#include <stdexcept>
#include <string>

namespace tlsph {

class InputError : public std::runtime_error {
 public:
  // where: the scene file (or "command line"); section and key may be empty.
  InputError(const std::string& where, const std::string& section, const std::string& key,
             const std::string& problem)
      : std::runtime_error(format(where, section, key, problem)) {}

 private:
  static std::string format(const std::string& where, const std::string& section,
                            const std::string& key, const std::string& problem) {
    std::string location = where;
    if (!section.empty()) location += ": [" + section + "]";
    if (!key.empty()) location += " " + key;
    return location + ": " + problem;
  }
};

}  // namespace tlsph
