#include "compare/Comparison.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "compare/FemSolution.hpp"
#include "compare/FieldLayout.hpp"
#include "compare/ParticleFrame.hpp"

namespace tlsph {

namespace {

std::string boundsText(const std::array<double, 6>& b) {
  std::ostringstream s;
  s.precision(4);
  s << "[" << b[0] << ", " << b[1] << "] x [" << b[2] << ", " << b[3] << "] x [" << b[4] << ", "
    << b[5] << "]";
  return s.str();
}

std::string femArrayOf(const CompareRequest& request, std::string_view field) {
  const auto it = request.femArrays.find(std::string(field));
  return it != request.femArrays.end() ? it->second : std::string(field);
}

}  // namespace

Comparison compareWithFem(const CompareRequest& request) {
  for (const auto& [field, array] : request.femArrays) {
    if (!findComparableField(field))
      throw std::runtime_error("--fem-fields " + field + "=" + array + ": '" + field +
                               "' is not a field compare knows; expected one of " +
                               comparableFieldList());
    if (array.empty())
      throw std::runtime_error("--fem-fields " + field + "=: the FEM array name is empty");
  }

  std::vector<const ComparableField*> wanted;
  for (const auto& name : request.fields) {
    const ComparableField* field = findComparableField(name);
    if (!field)
      throw std::runtime_error("--fields: '" + name + "' is not a field compare knows; " +
                               "expected one or more of " + comparableFieldList());
    if (std::find(wanted.begin(), wanted.end(), field) != wanted.end())
      throw std::runtime_error("--fields: '" + name + "' given twice");
    wanted.push_back(field);
  }

  Comparison c;
  c.frame = chooseFrame(request.run, request.frame);
  const ParticleFrame frame = readParticleFrame(c.frame.file);
  const FemSolution fem = FemSolution::read(request.fem);
  c.time = frame.time;
  c.step = frame.step;
  c.femFile = request.fem;
  c.femPoints = fem.grid()->GetNumberOfPoints();
  c.femCells = fem.grid()->GetNumberOfCells();
  c.femBounds = fem.bounds();
  c.probeTolerance = fem.probeTolerance();
  const std::string frameName = "tlsph frame " + frame.file.string();

  // Which fields, from which FEM arrays.
  std::vector<FemFieldRequest> requests;
  auto want = [&](const ComparableField& field) {
    requests.push_back({&field, femArrayOf(request, field.name)});
  };
  if (request.fields.empty()) {
    for (const auto& field : comparableFields()) {
      const bool inFrame = frame.field(field.name) != nullptr;
      const std::string array = femArrayOf(request, field.name);
      const bool inFem = fem.hasArray(array);
      if (field.name == "displacement" || (inFrame && inFem)) {
        want(field);
      } else if (inFrame || inFem) {
        c.notes.push_back(std::string(field.name) + ": not compared, " +
                          (inFrame ? "the FEM file has no array '" + array +
                                         "' (name it with --fem-fields " + std::string(field.name) +
                                         "=NAME)"
                                   : "the tlsph frame does not have it (add it to the scene's "
                                     "[output] fields)"));
      }
    }
  } else {
    for (const ComparableField* field : wanted)
      want(*field);
  }
  for (const auto& r : requests) {
    const PointField* f = frame.field(r.field->name);
    if (!f)
      throw std::runtime_error(frameName + " has no point field '" + std::string(r.field->name) +
                               "'; add " + std::string(r.field->name) +
                               " to the scene's [output] fields and run it again");
    if (f->components != r.field->components)
      throw std::runtime_error(frameName + ": '" + std::string(r.field->name) + "' has " +
                               std::to_string(f->components) + " components, expected " +
                               std::to_string(r.field->components));
  }

  // The body particles: ghosts are outside the body by construction.
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (frame.ghost[i]) {
      ++c.ghosts;
      continue;
    }
    c.frameIndex.push_back(i);
    c.reference.push_back(frame.reference[i]);
  }
  if (!frame.hasGhostFlags)
    c.warnings.push_back(frameName +
                         " has no ghost flags (add flags to the scene's [output] fields): "
                         "clamp ghosts, if any, count as particles outside the FEM mesh");

  ProbedFields probed = probeFemFields(fem, c.reference, requests);
  c.inside = std::move(probed.inside);
  for (const auto flag : c.inside)
    c.insideCount += flag;
  for (auto& note : probed.notes)
    c.notes.push_back(std::move(note));

  const std::size_t n = c.bodyParticles();
  if (c.insideCount == 0) {
    std::array<double, 6> b{1e300, -1e300, 1e300, -1e300, 1e300, -1e300};
    for (const auto& x : c.reference)
      for (int a = 0; a < 3; ++a) {
        b[2 * a] = std::min(b[2 * a], x[a]);
        b[2 * a + 1] = std::max(b[2 * a + 1], x[a]);
      }
    throw std::runtime_error(
        "none of the " + std::to_string(n) + " particles of " + frameName +
        " lies inside the FEM mesh of " + request.fem.string() + " (mesh bounds " +
        boundsText(c.femBounds) + ", particles' reference positions " + boundsText(b) +
        "); the FEM mesh must be the undeformed body, in metres, in the scene's coordinates");
  }
  const std::size_t outside = n - c.insideCount;
  if (outside * 100 > n) {
    std::ostringstream w;
    w.precision(3);
    w << outside << " of " << n << " particles (" << 100.0 * outside / n
      << " %) lie outside the FEM mesh and are not compared (mesh bounds "
      << boundsText(c.femBounds) << "); is " << request.fem.string()
      << " the whole undeformed body?";
    c.warnings.push_back(w.str());
  }

  for (std::size_t k = 0; k < requests.size(); ++k) {
    const ComparableField& field = *requests[k].field;
    const PointField& all = *frame.field(field.name);
    ComparedField compared;
    compared.tlsph = PointField{std::string(field.name), field.components, {}};
    compared.tlsph.values.reserve(n * field.components);
    for (const std::size_t i : c.frameIndex)
      compared.tlsph.values.insert(compared.tlsph.values.end(),
                                   all.values.begin() + i * field.components,
                                   all.values.begin() + (i + 1) * field.components);
    compared.fem = std::move(probed.fields[k]);
    compared.errors = compareField(std::string(field.name), field.components, compared.tlsph.values,
                                   compared.fem.values, c.inside, c.reference);
    c.fields.push_back(std::move(compared));
  }
  return c;
}

}  // namespace tlsph
