#include "scene/Config.hpp"

#include <algorithm>
#include <boost/program_options.hpp>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "scene/InputError.hpp"

namespace tlsph {

namespace po = boost::program_options;

namespace {

// Sections whose second component is a user-chosen name: [material.steel], [region.tip], ...
const std::set<std::string> kNamedKinds = {"material",  "body", "hole",    "region", "clamp",
                                           "prescribe", "load", "initial", "probe"};

std::pair<std::string, std::string> splitKey(const std::string& dotted) {
  const auto first = dotted.find('.');
  if (first == std::string::npos) return {"", dotted};
  const std::string kind = dotted.substr(0, first);
  if (kNamedKinds.count(kind)) {
    const auto second = dotted.find('.', first + 1);
    if (second == std::string::npos) return {kind + ".", dotted.substr(first + 1)};
    return {dotted.substr(0, second), dotted.substr(second + 1)};
  }
  return {kind, dotted.substr(first + 1)};
}

// A line quoted in a message: control and non-ASCII bytes (a binary file) as \xNN, cut short.
std::string printable(const std::string& line) {
  std::string out;
  for (const char c : line.substr(0, 60)) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      static const char* hex = "0123456789abcdef";
      out += std::string("\\x") + hex[u >> 4] + hex[u & 15];
    }
  }
  return line.size() > 60 ? out + "..." : out;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

}  // namespace

Config Config::read(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  std::error_code status;
  if (!std::filesystem::exists(file, status))
    throw InputError(file.string(), "", "", "cannot open the scene file: no such file");
  if (std::filesystem::is_directory(file, status))
    throw InputError(file.string(), "", "", "is a directory, not a scene file");
  std::ifstream in(file);
  if (!in)
    throw InputError(file.string(), "", "",
                     "cannot open the scene file: " + std::string(std::strerror(errno)));
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad())
    throw InputError(file.string(), "", "",
                     "cannot read the scene file: " + std::string(std::strerror(errno)));
  return parse(text.str(), file.string(), overrides);
}

Config Config::parse(const std::string& text, const std::string& origin,
                     const std::vector<std::string>& overrides) {
  Config config;
  config.origin_ = origin;
  // Boost reports keys but neither empty sections ([static] alone switches a static run on)
  // nor line numbers: one pass over the lines records both.
  // The same pass rejects what Boost would report without a line (a line that is neither a
  // header nor a key) or accept silently (a key given twice: the last would win).
  std::map<std::string, int> lineOf;
  {
    std::istringstream in(text);
    std::string line, section;
    bool sections = false;
    for (int number = 1; std::getline(in, line); ++number) {
      line = trim(line.substr(0, line.find('#')));
      const std::string here = origin + ":" + std::to_string(number);
      if (line.empty()) continue;
      if (line.size() >= 2 && line.front() == '[' && line.back() == ']') {
        // A header may appear again (its keys are merged), but not a key.
        section = trim(line.substr(1, line.size() - 2));
        if (section.empty()) throw InputError(here, "", "", "empty section name '[]'");
        sections = true;
        config.addSection(section, here);
      } else if (const auto eq = line.find('='); eq != std::string::npos) {
        const std::string key = trim(line.substr(0, eq));
        if (key.empty()) throw InputError(here, section, "", "a key is missing before '='");
        const std::string dotted = section.empty() ? key : section + "." + key;
        if (const auto first = lineOf.find(dotted); first != lineOf.end())
          throw InputError(here, section, key,
                           "key given twice (first at line " + std::to_string(first->second) +
                               "); remove one of them");
        lineOf[dotted] = number;
      } else {
        throw InputError(here, section, "",
                         "expected '[section]' or 'key = value', got '" + printable(line) + "'");
      }
    }
    if (!sections && lineOf.empty())
      throw InputError(origin, "", "", "the scene file is empty (no [section] and no key)");
  }
  po::options_description none;
  try {
    std::istringstream in(text);
    const auto parsed = po::parse_config_file(in, none, /*allow_unregistered=*/true);
    for (const auto& option : parsed.options) {
      if (option.value.size() != 1)
        throw InputError(origin, "", option.string_key, "expected exactly one value");
      const auto line = lineOf.find(option.string_key);
      config.set(option.string_key, option.value[0],
                 line == lineOf.end() ? origin : origin + ":" + std::to_string(line->second));
    }
  } catch (const po::error& e) {
    throw InputError(origin, "", "", std::string("not a valid scene file: ") + e.what());
  }
  for (std::string o : overrides) {
    if (o.rfind("--", 0) == 0) o = o.substr(2);
    const auto eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("command line", "", o, "an override must look like --section.key=value");
    const std::string key = trim(o.substr(0, eq));
    if (splitKey(key).first.empty() || splitKey(key).second.empty())
      throw InputError("command line", "", key,
                       "an override must name a section and a key, e.g. --time.end=0.5");
    config.set(key, trim(o.substr(eq + 1)), "command line");
  }
  return config;
}

void Config::addSection(const std::string& section, const std::string& where) {
  const std::string kind = section.substr(0, section.find('.'));
  if (kNamedKinds.count(kind) && section.find('.') == std::string::npos)
    throw InputError(where, section, "",
                     "sections of this kind need a name, e.g. [" + section + ".main]");
  if (!entries_.count(section)) {
    entries_[section];
    order_.push_back(section);
  }
  sectionWhere_.emplace(section, where);
}

void Config::set(const std::string& dottedKey, const std::string& value,
                 const std::string& origin) {
  const auto [section, key] = splitKey(dottedKey);
  if (section.empty())
    throw InputError(origin, "", dottedKey,
                     "every key must be inside a section such as [scene] or [material.NAME]");
  if (section.back() == '.')
    throw InputError(origin, section.substr(0, section.size() - 1), key,
                     "sections of this kind need a name, e.g. [" + section + "main]");
  const auto dot = section.find('.');
  if (dot != std::string::npos) {
    const std::string name = section.substr(dot + 1);
    if (!std::all_of(name.begin(), name.end(), [](char c) {
          return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
        }))
      throw InputError(origin, section, key,
                       "a section name may hold only letters, digits, '_' and '-'");
  }
  if (!entries_.count(section)) order_.push_back(section);
  entries_[section][key] = ConfigEntry{trim(value), origin};
}

std::vector<std::string> Config::namesOf(const std::string& kind) const {
  std::vector<std::string> names;
  for (const auto& s : order_)
    if (s.rfind(kind + ".", 0) == 0) names.push_back(s.substr(kind.size() + 1));
  return names;
}

bool Config::has(const std::string& section, const std::string& key) const {
  return find(section, key) != nullptr;
}

const ConfigEntry* Config::find(const std::string& section, const std::string& key) const {
  const auto s = entries_.find(section);
  if (s == entries_.end()) return nullptr;
  const auto k = s->second.find(key);
  if (k == s->second.end()) return nullptr;
  used_.insert({section, key});
  return &k->second;
}

const std::string& Config::get(const std::string& section, const std::string& key) const {
  const ConfigEntry* e = find(section, key);
  if (!e) throw InputError(origin_, section, key, "missing required key");
  return e->value;
}

std::string Config::where(const std::string& section, const std::string& key) const {
  const auto s = entries_.find(section);
  if (s != entries_.end()) {
    const auto k = s->second.find(key);
    if (k != s->second.end()) return k->second.origin;
  }
  // A missing key: point at the section's header if it has one.
  const auto header = sectionWhere_.find(section);
  return header != sectionWhere_.end() ? header->second : origin_;
}

std::vector<std::string> Config::keys(const std::string& section) const {
  std::vector<std::string> out;
  const auto s = entries_.find(section);
  if (s != entries_.end())
    for (const auto& [key, entry] : s->second)
      out.push_back(key);
  return out;
}

std::vector<std::pair<std::string, std::string>> Config::settings() const {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [section, keys] : entries_)
    for (const auto& [key, entry] : keys)
      out.emplace_back(section + "." + key, entry.value);
  return out;
}

std::vector<std::string> Config::unusedKeys(const std::string& section) const {
  std::vector<std::string> out;
  for (const auto& key : keys(section))
    if (!used_.count({section, key})) out.push_back(key);
  return out;
}

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t bestDistance = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const auto& c : candidates) {
    const std::size_t d = editDistance(word, c);
    if (d < bestDistance) {
      bestDistance = d;
      best = c;
    }
  }
  return best;
}

}  // namespace tlsph
