// The fields `tlsph compare` knows: their names, component layouts, units and norms, and the
// layouts an FEM file may use for them.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace tlsph {

struct ComparableField {
  std::string_view name;  // as in tlsph frames: "displacement", "cauchy_stress"
  int components;         // in tlsph frames: 3 (vector) or 9 (tensor, row-major)
  std::string_view unit;
  std::string_view norm;  // what |value| means for a particle
};

// displacement (3, m, Euclidean norm), cauchy_stress (9, Pa, Frobenius norm), in that order.
const std::vector<ComparableField>& comparableFields();

// nullptr if `name` is not a comparable field.
const ComparableField* findComparableField(std::string_view name);

// "displacement, cauchy_stress": for messages.
std::string comparableFieldList();

// Whether an FEM array with `components` components can hold `field`: displacement 3 (or 2,
// in-plane, z = 0); cauchy_stress 9 (row-major) or 6 (symmetric, VTK order xx yy zz xy yz xz).
bool acceptsFemLayout(const ComparableField& field, int components);

// What acceptsFemLayout accepts, for messages: "3 components (x y z) or 2 (x y)".
std::string femLayoutText(const ComparableField& field);

// Converts one FEM tuple of an accepted layout to the tlsph layout (field.components values).
void toTlsphLayout(const ComparableField& field, int components, const double* in, double* out);

}  // namespace tlsph
