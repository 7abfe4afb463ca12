// `tlsph compare RUN FEM.vtu [options]`: the command line of the field comparison with an FEM
// result (docs/compare.md). The work is in src/compare/.
#pragma once

#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "compare/Comparison.hpp"
#include "compare/ComparisonFrame.hpp"
#include "compare/ComparisonReport.hpp"
#include "output/VtuFile.hpp"

namespace tlsph {

inline constexpr const char* kCompareUsage =
    R"(usage: tlsph compare RUN FEM [options]

Compares a tlsph frame with an FEM solution, field by field, at the particles' reference
positions (docs/compare.md).

  RUN    a tlsph output directory, its .pvd series, or one .vtu (.pvtu) frame
  FEM    the FEM solution on the undeformed mesh: VTK XML (.vtu) or legacy (.vtk)
         unstructured grid with point (or cell) arrays displacement [m] and, optionally,
         cauchy_stress [Pa] (9 components row-major, or 6: xx yy zz xy yz xz)

options:
  --fields LIST          fields to compare, comma-separated: displacement, cauchy_stress
                         (default: displacement, plus cauchy_stress if both files have it)
  --fem-fields MAP       FEM array names, e.g. displacement=U,cauchy_stress=S
  --frame last|N         frame N (0-based) of the series (default: last)
  --output FILE.vtu      errors per particle for ParaView (default:
                         compare_<frame>_vs_<fem>.vtu next to the frame)
  --no-output            do not write the .vtu
  --json FILE            the numbers as JSON

exit status: 0 compared, 1 bad input (nothing written)
)";

namespace detail {

inline std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  std::string item;
  for (const char c : text + ",") {
    if (c == ',' || c == ' ') {
      if (!item.empty()) items.push_back(item);
      item.clear();
    } else {
      item += c;
    }
  }
  return items;
}

inline bool samePath(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code errorA, errorB;
  const auto canonicalA = std::filesystem::weakly_canonical(a, errorA);
  const auto canonicalB = std::filesystem::weakly_canonical(b, errorB);
  return !errorA && !errorB && canonicalA == canonicalB;
}

}  // namespace detail

// args: what follows "compare" on the command line. Returns the exit status.
inline int runCompare(const std::vector<std::string>& args) {
  namespace fs = std::filesystem;
  CompareRequest request;
  std::optional<fs::path> output, json;
  bool writeOutput = true;
  std::vector<std::string> positional;
  try {
    for (std::size_t k = 0; k < args.size(); ++k) {
      std::string option = args[k], value;
      if (option == "--help" || option == "-h") {
        std::cout << kCompareUsage;
        return 0;
      }
      if (option.rfind("--", 0) != 0) {
        positional.push_back(option);
        continue;
      }
      if (option == "--no-output") {
        writeOutput = false;
        continue;
      }
      const auto eq = option.find('=');
      if (eq != std::string::npos) {
        value = option.substr(eq + 1);
        option.erase(eq);
      }
      if (option != "--fields" && option != "--fem-fields" && option != "--frame" &&
          option != "--output" && option != "--json")
        throw std::runtime_error("unknown option " + option + "; see tlsph compare --help");
      if (eq == std::string::npos) {
        if (k + 1 == args.size())
          throw std::runtime_error(option + " needs a value; see tlsph compare --help");
        value = args[++k];
      }
      if (option == "--fields") {
        request.fields = detail::splitList(value);
        if (request.fields.empty()) throw std::runtime_error("--fields: no field given");
      } else if (option == "--fem-fields") {
        for (const auto& pair : detail::splitList(value)) {
          const auto split = pair.find('=');
          if (split == std::string::npos)
            throw std::runtime_error("--fem-fields " + value +
                                     ": expected FIELD=ARRAY[,...], "
                                     "e.g. displacement=U,cauchy_stress=S");
          request.femArrays[pair.substr(0, split)] = pair.substr(split + 1);
        }
      } else if (option == "--frame") {
        request.frame = value;
      } else if (option == "--output") {
        output = value;
      } else {
        json = value;
      }
    }
    if (positional.size() != 2)
      throw std::runtime_error(
          "expected 'compare RUN FEM' (a tlsph output directory, .pvd or "
          ".vtu, and the FEM .vtu/.vtk); see tlsph compare --help");
    request.run = positional[0];
    request.fem = positional[1];
    if (output && !writeOutput)
      throw std::runtime_error("--output and --no-output exclude each other");
    if (output && output->extension() != ".vtu")
      throw std::runtime_error("--output " + output->string() + ": expected a .vtu file name");

    const Comparison c = compareWithFem(request);
    const fs::path vtu = output ? *output : defaultComparisonFile(c);
    auto refuse = [&](const fs::path& file, const char* what) {
      if (detail::samePath(file, c.frame.file) || detail::samePath(file, request.fem))
        throw std::runtime_error(std::string(what) + " " + file.string() +
                                 " would overwrite an input file");
    };
    if (writeOutput) refuse(vtu, "--output");
    if (json) refuse(*json, "--json");
    if (json && writeOutput && detail::samePath(*json, vtu))
      throw std::runtime_error("--json and --output name the same file " + json->string());

    printComparison(std::cout, c);
    for (const auto& warning : c.warnings)
      std::cerr << "tlsph compare: warning: " << warning << "\n";
    std::cout << "\n";
    if (writeOutput) {
      writeVtuFile(comparisonFrame(c), vtu);
      std::cout << "wrote         " << vtu.string() << "\n";
    }
    if (json) {
      writeComparisonJson(c, *json);
      std::cout << "wrote         " << json->string() << "\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "tlsph compare: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace tlsph
