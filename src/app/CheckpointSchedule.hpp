// When a run writes checkpoints and where: OUTPUT/checkpoints/NAME_stepNNNNNNNNN.ckpt every
// [checkpoint] every_steps steps (Newton: load steps) and every every_seconds of wall time,
// the newest `keep` kept. `--restart=latest` finds the newest.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "io/CheckpointArchive.hpp"
#include "scene/SceneSetup.hpp"

namespace tlsph {

class CheckpointSchedule {
 public:
  CheckpointSchedule(const std::filesystem::path& outputDirectory, std::string name,
                     const CheckpointSettings& settings)
      : directory_(outputDirectory / "checkpoints"),
        name_(std::move(name)),
        settings_(settings),
        last_(Clock::now()) {}

  // Due after `count` steps (or load steps) when a step or wall-time interval has passed.
  bool due(long count) const {
    if (settings_.everySteps > 0 && count % settings_.everySteps == 0) return true;
    return settings_.everySeconds > 0.0 &&
           std::chrono::duration<double>(Clock::now() - last_).count() >= settings_.everySeconds;
  }

  std::filesystem::path fileFor(long step) const {
    char number[32];
    std::snprintf(number, sizeof number, "_step%09ld.ckpt", step);
    return directory_ / (name_ + number);
  }

  // After a checkpoint has been written: restarts the wall-time interval and removes all but
  // the newest `keep` checkpoints of this scene.
  void written() {
    last_ = Clock::now();
    auto files = existing(directory_, name_);
    const auto keep = static_cast<std::size_t>(std::max(1L, settings_.keep));
    std::error_code ignored;
    for (std::size_t k = 0; k + keep < files.size(); ++k)
      std::filesystem::remove(files[k], ignored);
  }

  const std::filesystem::path& directory() const { return directory_; }

  // Checkpoints of scene `name` in `directory`, oldest (lowest step) first.
  static std::vector<std::filesystem::path> existing(const std::filesystem::path& directory,
                                                     const std::string& name) {
    std::vector<std::filesystem::path> files;
    std::error_code status;
    if (!std::filesystem::is_directory(directory, status)) return files;
    const std::string prefix = name + "_step";
    for (const auto& entry : std::filesystem::directory_iterator(directory, status)) {
      const std::string file = entry.path().filename().string();
      if (file.size() == prefix.size() + 9 + 5 && file.rfind(prefix, 0) == 0 &&
          file.compare(file.size() - 5, 5, ".ckpt") == 0)
        files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());  // zero-padded step numbers sort as numbers
    return files;
  }

  // The newest checkpoint of scene `name` under an output directory; throws CheckpointError
  // when there is none.
  static std::filesystem::path latest(const std::filesystem::path& outputDirectory,
                                      const std::string& name) {
    const auto files = existing(outputDirectory / "checkpoints", name);
    if (files.empty())
      throw CheckpointError("--restart=latest: no checkpoint of scene '" + name + "' in " +
                            (outputDirectory / "checkpoints").string());
    return files.back();
  }

 private:
  using Clock = std::chrono::steady_clock;
  std::filesystem::path directory_;
  std::string name_;
  CheckpointSettings settings_;
  Clock::time_point last_;
};

}  // namespace tlsph
