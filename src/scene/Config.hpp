// A scene file as sections of key = value entries, read with Boost.Program_options
// (INI style), with command-line overrides `--section.key=value`. It checks nothing about
// meaning: SceneBuilder asks for the keys it knows and reports the ones left over.
#pragma once

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace tlsph {

struct ConfigEntry {
  std::string value;
  std::string origin;  // "scene.ini:12" (file and line), or "command line"
};

class Config {
 public:
  // Throws InputError if the file cannot be read or is not valid INI, or an override is
  // malformed. Overrides look like "--time.end=0.5" or "time.end=0.5".
  static Config read(const std::filesystem::path& file,
                     const std::vector<std::string>& overrides = {});
  static Config parse(const std::string& text, const std::string& origin,
                      const std::vector<std::string>& overrides = {});

  const std::string& origin() const { return origin_; }

  // Section names in file order of first appearance, e.g. "scene", "material.steel".
  const std::vector<std::string>& sections() const { return order_; }
  bool hasSection(const std::string& section) const { return entries_.count(section) > 0; }
  // Sections "kind.NAME" of a kind, with their names.
  std::vector<std::string> namesOf(const std::string& kind) const;

  bool has(const std::string& section, const std::string& key) const;
  // The raw value; marks the key as used. Throws InputError if missing.
  const std::string& get(const std::string& section, const std::string& key) const;
  const ConfigEntry* find(const std::string& section, const std::string& key) const;
  std::string where(const std::string& section, const std::string& key) const;

  // Keys of a section nobody asked for (typos, keys of another shape): the builder
  // reports them with a did-you-mean.
  std::vector<std::string> unusedKeys(const std::string& section) const;
  std::vector<std::string> keys(const std::string& section) const;
  // Every entry as ("section.key", value), sorted; does not mark anything used.
  std::vector<std::pair<std::string, std::string>> settings() const;
  // A copy with one key set (as a command-line override would), e.g. a coarser scene.dx.
  Config with(const std::string& dottedKey, const std::string& value,
              const std::string& origin) const {
    Config c = *this;
    c.set(dottedKey, value, origin);
    return c;
  }

 private:
  void addSection(const std::string& section, const std::string& where);
  void set(const std::string& dottedKey, const std::string& value, const std::string& origin);

  std::string origin_;
  std::map<std::string, std::map<std::string, ConfigEntry>> entries_;
  std::vector<std::string> order_;
  std::map<std::string, std::string> sectionWhere_;  // "file:line" of each section's header
  mutable std::set<std::pair<std::string, std::string>> used_;
};

// Levenshtein distance, for did-you-mean suggestions.
std::size_t editDistance(const std::string& a, const std::string& b);
// The closest candidate if it is close enough to be a likely typo, else "".
std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace tlsph
