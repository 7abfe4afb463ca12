#include "compare/ComparisonFrame.hpp"

#include <cmath>
#include <limits>

namespace tlsph {

Frame comparisonFrame(const Comparison& c) {
  const std::size_t n = c.bodyParticles();
  Frame frame;
  frame.time = std::isnan(c.time) ? 0.0 : c.time;
  frame.step = c.step < 0 ? 0 : c.step;
  frame.points = c.reference;
  for (const auto& f : c.fields) {
    const int m = f.tlsph.components;
    PointField error{"error_" + f.tlsph.name, m, std::vector<double>(n * m)};
    PointField magnitude{"error_" + f.tlsph.name + "_magnitude", 1, std::vector<double>(n)};
    for (std::size_t i = 0; i < n; ++i) {
      double sum = 0.0;
      for (int k = 0; k < m; ++k) {
        const double e = f.tlsph.values[i * m + k] - f.fem.values[i * m + k];  // NaN outside
        error.values[i * m + k] = e;
        sum += e * e;
      }
      magnitude.values[i] = std::sqrt(sum);
    }
    frame.fields.push_back(PointField{"fem_" + f.fem.name, m, f.fem.values});
    frame.fields.push_back(PointField{"tlsph_" + f.tlsph.name, m, f.tlsph.values});
    frame.fields.push_back(std::move(error));
    frame.fields.push_back(std::move(magnitude));
  }
  frame.flags.push_back(PointFlags{"compared", c.inside});
  return frame;
}

std::filesystem::path defaultComparisonFile(const Comparison& c) {
  return c.frame.file.parent_path() /
         ("compare_" + c.frame.file.stem().string() + "_vs_" + c.femFile.stem().string() + ".vtu");
}

}  // namespace tlsph
