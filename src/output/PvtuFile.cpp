#include "output/PvtuFile.hpp"

#include <bit>
#include <set>
#include <stdexcept>

#include "io/AtomicFile.hpp"
#include "io/XmlText.hpp"

namespace tlsph {

void writePvtuFile(const Frame& layout, const std::vector<std::string>& pieces,
                   const std::filesystem::path& file) {
  std::set<std::string> names;
  auto array = [&](const std::string& type, const std::string& name, int components) {
    if (name.empty() || !names.insert(name).second)
      throw std::invalid_argument("point array '" + name + "' unnamed or given twice in the " +
                                  "index " + file.string());
    return "      <PDataArray type=\"" + type + "\" Name=\"" + xmlAttribute(name) +
           "\" NumberOfComponents=\"" + std::to_string(components) + "\"/>\n";
  };
  // The same header as the pieces' (VtuFile.cpp: UInt64 block headers, zlib).
  std::string text =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" ";
  text += std::endian::native == std::endian::little ? "byte_order=\"LittleEndian\""
                                                     : "byte_order=\"BigEndian\"";
  text += " header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n";
  text += "  <PUnstructuredGrid GhostLevel=\"0\">\n    <PPointData>\n";
  for (const auto& field : layout.fields)
    text += array("Float64", field.name, field.components);
  for (const auto& flags : layout.flags)
    text += array("UInt8", flags.name, 1);
  if (layout.ids) text += array("Int64", "id", 1);
  text += "    </PPointData>\n    <PPoints>\n";
  text += "      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n";
  text += "    </PPoints>\n";
  for (const auto& piece : pieces)
    text += "    <Piece Source=\"" + xmlAttribute(piece) + "\"/>\n";
  text += "  </PUnstructuredGrid>\n</VTKFile>\n";

  writeTextAtomically(file, {text}, "PVTU");
}

}  // namespace tlsph
