#include "compare/ComparisonReport.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "compare/FieldLayout.hpp"
#include "io/AtomicFile.hpp"
#include "io/JsonText.hpp"

namespace tlsph {

namespace {

// Four significant digits; "n/a" for NaN (a zero reference has no relative error).
std::string number(double v) {
  if (std::isnan(v)) return "n/a";
  std::ostringstream s;
  s << std::scientific << std::setprecision(3) << v;
  return s.str();
}

std::string point(const std::array<double, 3>& x) {
  std::ostringstream s;
  s << std::setprecision(6) << "(" << x[0] << ", " << x[1] << ", " << x[2] << ")";
  return s.str();
}

}  // namespace

void printComparison(std::ostream& out, const Comparison& c) {
  out << "tlsph frame   " << c.frame.file.string();
  std::vector<std::string> about;
  if (!c.frame.series.empty())
    about.push_back("frame " + std::to_string(c.frame.index) + " of 0.." +
                    std::to_string(c.frame.count - 1));
  if (!std::isnan(c.time)) {
    std::ostringstream t;
    t << "t = " << c.time << " s";
    about.push_back(t.str());
  }
  if (c.step >= 0) about.push_back("step " + std::to_string(c.step));
  for (std::size_t k = 0; k < about.size(); ++k)
    out << (k == 0 ? " (" : ", ") << about[k] << (k + 1 == about.size() ? ")" : "");
  out << "\nFEM solution  " << c.femFile.string() << " (" << c.femPoints << " points, "
      << c.femCells << " cells)\n"
      << "particles     " << c.bodyParticles() << " body particles";
  if (c.ghosts > 0) out << " (" << c.ghosts << " ghosts left out)";
  out << ": " << c.insideCount << " inside the FEM mesh and compared, "
      << c.bodyParticles() - c.insideCount << " outside and skipped\n";
  for (const auto& note : c.notes)
    out << "note          " << note << "\n";
  out << "Errors e = tlsph - fem at the particles' reference positions; sums over particles "
         "unweighted\n(lattice particles share one volume, so this is the volume-weighted "
         "norm).\n";

  for (const auto& f : c.fields) {
    const FieldErrors& e = f.errors;
    const ComparableField& field = *findComparableField(e.field);
    std::string unit = " ";  // (" " + string trips GCC 12's -Wrestrict false positive)
    unit += field.unit;
    out << "\n" << e.field << " [" << field.unit << "], |.| = " << field.norm << "\n";
    auto row = [&](const char* what, const std::string& value, const std::string& more = "") {
      out << "  " << std::left << std::setw(24) << what << std::setw(more.empty() ? 0 : 16) << value
          << more << "\n";
    };
    row("particles compared", std::to_string(e.compared));
    row("L2 error (relative)", number(e.l2Relative), "sqrt(sum |e|^2 / sum |fem|^2)");
    row("RMS error", number(e.rmsAbsolute) + unit, "sqrt(mean |e|^2)");
    row("max error", number(e.maxAbsolute) + unit,
        "at X = " + point(e.maxAt) + ", particle " + std::to_string(c.frameIndex[e.maxIndex]));
    row("max |fem|", number(e.maxReference) + unit);
    row("max error / max |fem|", number(e.maxRelative));
  }
  out << std::right;
}

std::string comparisonJson(const Comparison& c) {
  std::ostringstream j;
  j << "{\n"
    << "  \"frame\": " << jsonText(c.frame.file.string()) << ",\n"
    << "  \"series\": " << jsonText(c.frame.series.string()) << ",\n"
    << "  \"frame_number\": " << c.frame.index << ",\n"
    << "  \"frames\": " << c.frame.count << ",\n"
    << "  \"time\": " << jsonNumber(c.time) << ",\n"
    << "  \"step\": " << c.step << ",\n"
    << "  \"fem\": " << jsonText(c.femFile.string()) << ",\n"
    << "  \"fem_points\": " << c.femPoints << ",\n"
    << "  \"fem_cells\": " << c.femCells << ",\n"
    << "  \"probe_tolerance\": " << jsonNumber(c.probeTolerance) << ",\n"
    << "  \"body_particles\": " << c.bodyParticles() << ",\n"
    << "  \"ghost_particles\": " << c.ghosts << ",\n"
    << "  \"compared_particles\": " << c.insideCount << ",\n"
    << "  \"outside_particles\": " << c.bodyParticles() - c.insideCount << ",\n"
    << "  \"error\": \"tlsph - fem\",\n"
    << "  \"weights\": \"equal (lattice particles share one volume)\",\n"
    << "  \"fields\": {";
  for (std::size_t k = 0; k < c.fields.size(); ++k) {
    const FieldErrors& e = c.fields[k].errors;
    const ComparableField& field = *findComparableField(e.field);
    j << (k == 0 ? "\n" : ",\n") << "    " << jsonText(e.field) << ": {\n"
      << "      \"unit\": " << jsonText(std::string(field.unit)) << ",\n"
      << "      \"norm\": " << jsonText(std::string(field.norm)) << ",\n"
      << "      \"compared\": " << e.compared << ",\n"
      << "      \"l2_relative\": " << jsonNumber(e.l2Relative) << ",\n"
      << "      \"rms_absolute\": " << jsonNumber(e.rmsAbsolute) << ",\n"
      << "      \"max_absolute\": " << jsonNumber(e.maxAbsolute) << ",\n"
      << "      \"max_at\": [" << jsonNumber(e.maxAt[0]) << ", " << jsonNumber(e.maxAt[1]) << ", "
      << jsonNumber(e.maxAt[2]) << "],\n"
      << "      \"max_particle\": " << c.frameIndex[e.maxIndex] << ",\n"
      << "      \"max_reference\": " << jsonNumber(e.maxReference) << ",\n"
      << "      \"max_relative\": " << jsonNumber(e.maxRelative) << "\n"
      << "    }";
  }
  j << (c.fields.empty() ? "},\n" : "\n  },\n");
  auto list = [&](const char* key, const std::vector<std::string>& lines, bool last) {
    j << "  " << jsonText(key) << ": [";
    for (std::size_t k = 0; k < lines.size(); ++k)
      j << (k == 0 ? "" : ", ") << jsonText(lines[k]);
    j << "]" << (last ? "\n" : ",\n");
  };
  list("notes", c.notes, false);
  list("warnings", c.warnings, true);
  j << "}\n";
  return j.str();
}

void writeComparisonJson(const Comparison& c, const std::filesystem::path& file) {
  const std::string text = comparisonJson(c);
  writeTextAtomically(file, {text}, "JSON");
}

}  // namespace tlsph
