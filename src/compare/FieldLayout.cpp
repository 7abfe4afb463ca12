#include "compare/FieldLayout.hpp"

#include <algorithm>

namespace tlsph {

const std::vector<ComparableField>& comparableFields() {
  static const std::vector<ComparableField> fields{
      {"displacement", 3, "m", "Euclidean norm of the vector"},
      {"cauchy_stress", 9, "Pa", "Frobenius norm of the 3x3 tensor"}};
  return fields;
}

const ComparableField* findComparableField(std::string_view name) {
  for (const auto& field : comparableFields())
    if (field.name == name) return &field;
  return nullptr;
}

std::string comparableFieldList() {
  std::string list;
  for (const auto& field : comparableFields())
    list += (list.empty() ? "" : ", ") + std::string(field.name);
  return list;
}

bool acceptsFemLayout(const ComparableField& field, int components) {
  if (field.components == 3) return components == 3 || components == 2;
  return components == 9 || components == 6;
}

std::string femLayoutText(const ComparableField& field) {
  if (field.components == 3) return "3 components (x y z) or 2 (x y, z = 0)";
  return "9 components (row-major xx xy xz yx yy yz zx zy zz) or 6 (symmetric, VTK order "
         "xx yy zz xy yz xz)";
}

void toTlsphLayout(const ComparableField& field, int components, const double* in, double* out) {
  if (field.components == 3) {
    out[0] = in[0];
    out[1] = in[1];
    out[2] = components == 3 ? in[2] : 0.0;
    return;
  }
  if (components == 9) {
    std::copy(in, in + 9, out);
    return;
  }
  // Voigt order of VTK and ParaView: xx yy zz xy yz xz.
  const double xx = in[0], yy = in[1], zz = in[2], xy = in[3], yz = in[4], xz = in[5];
  const double full[9] = {xx, xy, xz, xy, yy, yz, xz, yz, zz};
  std::copy(full, full + 9, out);
}

}  // namespace tlsph
