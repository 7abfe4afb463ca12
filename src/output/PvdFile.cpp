#include "output/PvdFile.hpp"

#include <bit>
#include <fstream>
#include <stdexcept>
#include <string>

#include "output/AtomicFile.hpp"
#include "output/RoundTripNumber.hpp"
#include "output/XmlText.hpp"

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

  try {
    writeAtomically(pvd, [&](const std::filesystem::path& temporary) {
      std::ofstream out(temporary, std::ios::binary);
      out.write(text.data(), static_cast<std::streamsize>(text.size()));
      out.close();
      if (!out) throw std::runtime_error("cannot write PVD file " + pvd.string());
    });
  } catch (const std::filesystem::filesystem_error& e) {
    throw std::runtime_error("cannot write PVD file " + pvd.string() + ": " + e.what());
  }
}

}  // namespace tlsph
