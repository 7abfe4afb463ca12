#include "output/PvdFile.hpp"

#include <bit>
#include <stdexcept>
#include <string>

#include "io/AtomicFile.hpp"
#include "io/RoundTripNumber.hpp"
#include "io/XmlText.hpp"

namespace tlsph {

void writePvdFile(const std::filesystem::path& pvd, const std::vector<PvdEntry>& entries) {
  std::string text = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" ";
  text += std::endian::native == std::endian::little ? "byte_order=\"LittleEndian\">\n"
                                                     : "byte_order=\"BigEndian\">\n";
  text += "  <Collection>\n";
  for (const auto& entry : entries)
    text += "    <DataSet timestep=\"" + roundTripText(entry.time) +
            "\" group=\"\" part=\"0\" file=\"" + xmlAttribute(entry.file.generic_string()) +
            "\"/>\n";
  text += "  </Collection>\n</VTKFile>\n";

  writeTextAtomically(pvd, {text}, "PVD");
}

}  // namespace tlsph
