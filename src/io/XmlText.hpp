// Text for the small XML index files written by hand (.pvd, .pvtu).
#pragma once

#include <string>

namespace tlsph {

// An attribute value with XML's specials escaped: file names come from user-chosen scene
// names, so they may hold any of them.
inline std::string xmlAttribute(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace tlsph
