// Typed reading of one scene-file section, with errors that name file, section and key.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/Types.hpp"
#include "scene/Config.hpp"
#include "scene/InputError.hpp"

namespace tlsph {

class SectionReader {
 public:
  SectionReader(const Config& config, std::string section)
      : config_(config), section_(std::move(section)) {}

  const std::string& section() const { return section_; }
  bool has(const std::string& key) {
    allowed_.insert(key);
    return config_.has(section_, key);
  }
  // Keys that are valid here although this reader did not ask for them.
  void allow(std::initializer_list<std::string> keys) { allowed_.insert(keys.begin(), keys.end()); }

  InputError error(const std::string& key, const std::string& problem) const {
    return InputError(config_.where(section_, key), section_, key, problem);
  }

  std::string word(const std::string& key, std::optional<std::string> fallback = std::nullopt,
                   const std::vector<std::string>& choices = {}) {
    allowed_.insert(key);
    const ConfigEntry* e = config_.find(section_, key);
    if (!e) {
      if (fallback) return *fallback;
      throw missing(key, choiceList(choices));
    }
    if (!choices.empty() && std::find(choices.begin(), choices.end(), e->value) == choices.end()) {
      std::string hint = closestMatch(e->value, choices);
      throw error(key, "'" + e->value + "' is not valid" + choiceList(choices) +
                           (hint.empty() ? "" : "; did you mean '" + hint + "'?"));
    }
    return e->value;
  }

  double number(const std::string& key, std::optional<double> fallback = std::nullopt) {
    allowed_.insert(key);
    const ConfigEntry* e = config_.find(section_, key);
    if (!e) {
      if (fallback) return *fallback;
      throw missing(key, " (a number)");
    }
    return toNumber(key, e->value);
  }
  double positive(const std::string& key, std::optional<double> fallback = std::nullopt) {
    const double v = number(key, fallback);
    if (!(v > 0.0))
      throw error(key, "must be a positive number, got " + config_.get(section_, key));
    return v;
  }
  double nonNegative(const std::string& key, std::optional<double> fallback = std::nullopt) {
    const double v = number(key, fallback);
    if (!(v >= 0.0))
      throw error(key, "must be zero or positive, got " + config_.get(section_, key));
    return v;
  }
  // A whole number in [0, most]; the default bound keeps every such number exact in a double.
  long integer(const std::string& key, std::optional<long> fallback = std::nullopt,
               long most = kLargestInteger) {
    const double v =
        number(key, fallback ? std::optional<double>(double(*fallback)) : std::nullopt);
    if (v != std::floor(v) || v < 0)
      throw error(key, "must be a whole number >= 0, got " + config_.get(section_, key));
    if (v > double(most))
      throw error(
          key, "must be at most " + std::to_string(most) + ", got " + config_.get(section_, key));
    return static_cast<long>(v);
  }
  static constexpr long kLargestInteger = 1L << 53;
  bool flag(const std::string& key, std::optional<bool> fallback = std::nullopt) {
    const std::string v = word(
        key, fallback ? std::optional<std::string>(*fallback ? "true" : "false") : std::nullopt);
    if (v == "true" || v == "yes" || v == "on" || v == "1") return true;
    if (v == "false" || v == "no" || v == "off" || v == "0") return false;
    throw error(key, "expected true or false, got '" + v + "'");
  }

  // Whitespace- or comma-separated numbers.
  std::vector<double> numbers(const std::string& key) {
    const std::string text = word(key);
    std::string spaced = text;
    for (char& c : spaced)
      if (c == ',' || c == ';') c = ' ';
    std::istringstream in(spaced);
    std::vector<double> out;
    std::string token;
    while (in >> token)
      out.push_back(toNumber(key, token));
    return out;
  }

  template <int D>
  Vec<D> vector(const std::string& key, std::optional<Vec<D>> fallback = std::nullopt) {
    allowed_.insert(key);
    if (!config_.has(section_, key)) {
      if (fallback) return *fallback;
      throw missing(key, " (a vector of " + std::to_string(D) + " numbers)");
    }
    const auto v = numbers(key);
    if (v.size() != D)
      throw error(key, "expected " + std::to_string(D) + " numbers (the scene is " +
                           std::to_string(D) + "D), got '" + config_.get(section_, key) + "'");
    Vec<D> out;
    for (int a = 0; a < D; ++a)
      out[a] = v[a];
    return out;
  }

  std::vector<std::string> words(const std::string& key, const std::vector<std::string>& fallback) {
    allowed_.insert(key);
    if (!config_.has(section_, key)) return fallback;
    std::string spaced = word(key);
    for (char& c : spaced)
      if (c == ',') c = ' ';
    std::istringstream in(spaced);
    std::vector<std::string> out;
    std::string token;
    while (in >> token)
      out.push_back(token);
    return out;
  }

  // Every key of the section must have been read or allowed.
  void finish() const {
    for (const auto& key : config_.unusedKeys(section_)) {
      if (allowed_.count(key)) continue;
      const std::string hint =
          closestMatch(key, std::vector<std::string>(allowed_.begin(), allowed_.end()));
      std::string known;
      for (const auto& k : allowed_)
        known += (known.empty() ? "" : ", ") + k;
      throw error(key, "unknown key" + (hint.empty() ? "" : "; did you mean '" + hint + "'?") +
                           " (keys here: " + known + ")");
    }
  }

 private:
  // A required key is absent; a leftover key that looks like it is most likely a typo.
  InputError missing(const std::string& key, const std::string& what) const {
    const std::string typo = closestMatch(key, config_.unusedKeys(section_));
    if (!typo.empty())
      return error(typo, "unknown key; did you mean '" + key + "'? (required here" + what + ")");
    return error(key, "missing required key" + what);
  }
  static std::string choiceList(const std::vector<std::string>& choices) {
    if (choices.empty()) return "";
    std::string s = "; expected one of: ";
    for (std::size_t i = 0; i < choices.size(); ++i)
      s += (i ? ", " : "") + choices[i];
    return s;
  }
  double toNumber(const std::string& key, const std::string& text) const {
    try {
      std::size_t used = 0;
      const double v = std::stod(text, &used);
      if (used == text.size()) {
        if (std::isfinite(v)) return v;
        throw error(key, "expected a finite number, got '" + text + "'");
      }
    } catch (const std::out_of_range&) {
      throw error(key,
                  "expected a number within the range of a double (about 1e-308 to "
                  "1e308 in magnitude, or 0), got '" +
                      text + "'");
    } catch (const std::invalid_argument&) {
    }
    throw error(key, "expected a number, got '" + text + "'");
  }

  const Config& config_;
  std::string section_;
  std::set<std::string> allowed_;
};

}  // namespace tlsph
