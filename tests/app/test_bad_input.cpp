// The bad-input catalogue (tests/bad-input/*.ini): every malformed or physically invalid scene
// is run through the built program (`tlsph check`, which builds the whole set-up without
// running) and must give the error or warning its header states, without crashing and, for an
// error, with exit status 1 and nothing written. The header's comment lines (format in
// tests/bad-input/README.md):
//   # expect: error | warning
//   # message: <substring the output must hold>       (one or more)
//   # args: <extra command-line arguments>            (optional, appended as given; {catalogue}
//                                                     stands for tests/bad-input)
//   # scene: <path instead of this file>              (optional, relative to tests/bad-input)
//   # command: check | run                            (optional, default check)
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "ProgramRunner.hpp"

namespace fs = std::filesystem;
using tlsph::testing::runProgram;

namespace {

const fs::path kCatalogue = fs::path(TLSPH_SOURCE_DIR) / "tests" / "bad-input";

struct Expectation {
  std::string expect;  // "error" or "warning"; empty if the file states none
  std::vector<std::string> messages;
  std::string args;
  fs::path scene;
  std::string command = "check";
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

Expectation readExpectation(const fs::path& file) {
  Expectation e;
  e.scene = file;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    line = trim(line);
    if (line.empty() || line[0] != '#') continue;
    line = trim(line.substr(1));
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon), value = trim(line.substr(colon + 1));
    if (key == "expect") e.expect = value;
    if (key == "message") e.messages.push_back(value);
    if (key == "args") {
      // {catalogue} stands for this directory (files the arguments name, e.g. checkpoints)
      std::string v = value;
      for (auto at = v.find("{catalogue}"); at != std::string::npos; at = v.find("{catalogue}"))
        v.replace(at, 11, kCatalogue.string());
      e.args += (e.args.empty() ? "" : " ") + v;
    }
    if (key == "scene") e.scene = file.parent_path() / value;
    if (key == "command") e.command = value;
  }
  return e;
}

std::vector<fs::path> catalogue() {
  std::vector<fs::path> files;
  if (fs::is_directory(kCatalogue))
    for (const auto& entry : fs::directory_iterator(kCatalogue))
      if (entry.path().extension() == ".ini") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

// A path for the shell, in single quotes.
std::string quoted(const fs::path& p) {
  std::string q = "'";
  q += p.string();
  q += '\'';
  return q;
}

class BadInput : public ::testing::TestWithParam<fs::path> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("tlsph_bad_input_" + std::to_string(::getpid()) + "_" + GetParam().stem().string());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
    // The program runs in an empty working directory, so that anything it writes (the default
    // output/NAME included) shows.
    previous_ = fs::current_path();
    fs::current_path(dir_ / "work");
  }
  void TearDown() override {
    fs::current_path(previous_);
    fs::remove_all(dir_);
  }
  fs::path dir_, previous_;
};

}  // namespace

TEST(BadInputCatalogue, HoldsAtLeastThirtyScenes) {
  EXPECT_GE(catalogue().size(), 30u);
}

TEST_P(BadInput, GivesItsMessage) {
  const fs::path file = GetParam();
  const Expectation e = readExpectation(file);
  ASSERT_TRUE(e.expect == "error" || e.expect == "warning")
      << file << ": the header needs '# expect: error' or '# expect: warning'";
  ASSERT_FALSE(e.messages.empty()) << file << ": the header needs at least one '# message: ...'";
  ASSERT_TRUE(e.command == "check" || e.command == "run") << file << ": command " << e.command;

  const auto r = runProgram(
      e.command + " " + quoted(e.scene) + (e.args.empty() ? "" : " " + e.args), dir_ / "log.txt");
  SCOPED_TRACE(file.filename().string() + ", output:\n" + r.output);
  EXPECT_NE(r.status, 134) << "aborted";
  EXPECT_NE(r.status, 139) << "segmentation fault";
  for (const char* crash : {"terminate called", "Segmentation fault", "Assertion", "core dumped"})
    EXPECT_EQ(r.output.find(crash), std::string::npos) << crash;
  for (const auto& message : e.messages)
    EXPECT_NE(r.output.find(message), std::string::npos) << "missing: " << message;
  if (e.expect == "error") {
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.output.find("tlsph: "), std::string::npos);
    EXPECT_TRUE(fs::is_empty(dir_ / "work")) << "the program wrote output for a bad scene";
  } else {
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.output.find("warning: "), std::string::npos);
  }
}

INSTANTIATE_TEST_SUITE_P(Catalogue, BadInput, ::testing::ValuesIn(catalogue()),
                         [](const ::testing::TestParamInfo<fs::path>& info) {
                           std::string name = info.param.stem().string();
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });
