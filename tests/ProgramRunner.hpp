// Running the built `tlsph` program from a test: its exit status and everything it printed.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace tlsph::testing {

struct ProgramResult {
  int status = -1;
  std::string output;  // stdout and stderr together
};

// Runs `tlsph ARGUMENTS` through the shell, its output captured in `log`.
inline ProgramResult runProgram(const std::string& arguments, const std::filesystem::path& log) {
  const std::string command =
      std::string(TLSPH_PROGRAM) + " " + arguments + " > " + log.string() + " 2>&1";
  ProgramResult r;
  r.status = WEXITSTATUS(std::system(command.c_str()));
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  r.output = text.str();
  return r;
}

}  // namespace tlsph::testing
