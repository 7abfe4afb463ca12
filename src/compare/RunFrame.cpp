#include "compare/RunFrame.hpp"

#include <vtkNew.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "output/VtkErrorLog.hpp"

namespace tlsph {

namespace fs = std::filesystem;

std::string lowerExtension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

namespace {

// The string value of `key` in a flat JSON object such as summary.json; "" if absent.
std::string jsonStringValue(const std::string& text, const std::string& key) {
  const std::string quoted = "\"" + key + "\"";
  std::size_t at = text.find(quoted);
  if (at == std::string::npos) return "";
  at = text.find_first_not_of(" \t\r\n", at + quoted.size());
  if (at == std::string::npos || text[at] != ':') return "";
  at = text.find_first_not_of(" \t\r\n", at + 1);
  if (at == std::string::npos || text[at] != '"') return "";
  std::string value;
  for (++at; at < text.size() && text[at] != '"'; ++at) {
    char c = text[at];
    if (c == '\\' && at + 1 < text.size()) {
      c = text[++at];
      if (c == 'n') c = '\n';
      if (c == 't') c = '\t';
    }
    value += c;
  }
  return value;
}

// The series of an output directory: summary.json's "pvd" (by file name: the path in the
// record is relative to where the run was started), or the directory's only .pvd.
fs::path seriesOfDirectory(const fs::path& dir) {
  const fs::path record = dir / "summary.json";
  if (fs::exists(record)) {
    std::ifstream in(record);
    std::stringstream text;
    text << in.rdbuf();
    const std::string pvd = jsonStringValue(text.str(), "pvd");
    if (pvd.empty())
      throw std::runtime_error(record.string() +
                               ": the run wrote no VTU frames (its \"pvd\" is empty); run it again "
                               "with [output] fields including displacement");
    const fs::path series = dir / fs::path(pvd).filename();
    if (!fs::exists(series))
      throw std::runtime_error(record.string() + " names the series " + pvd + ", but " +
                               series.string() + " does not exist");
    return series;
  }
  std::vector<fs::path> found;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file() && lowerExtension(entry.path()) == ".pvd")
      found.push_back(entry.path());
  if (found.size() == 1) return found.front();
  if (found.empty())
    throw std::runtime_error(dir.string() +
                             ": no summary.json and no .pvd series here; expected a directory "
                             "written by `tlsph run`, a .pvd or a .vtu file");
  std::sort(found.begin(), found.end());
  std::string names;
  for (const auto& f : found)
    names += (names.empty() ? "" : ", ") + f.filename().string();
  throw std::runtime_error(dir.string() + ": no summary.json and several .pvd series (" + names +
                           "); give the .pvd file instead");
}

}  // namespace

std::vector<PvdEntry> readPvdFile(const fs::path& pvd) {
  vtkNew<vtkXMLDataParser> parser;
  VtkErrorLog errors(parser);
  parser->SetFileName(pvd.c_str());
  if (parser->Parse() != 1 || !parser->GetRootElement())
    throw std::runtime_error("cannot read PVD file " + pvd.string() +
                             (errors.empty() ? std::string() : ": " + errors.text()));
  vtkXMLDataElement* root = parser->GetRootElement();
  const char* type = root->GetAttribute("type");
  vtkXMLDataElement* collection = root->FindNestedElementWithName("Collection");
  if (std::string(root->GetName()) != "VTKFile" || !type || std::string(type) != "Collection" ||
      !collection)
    throw std::runtime_error(pvd.string() +
                             " is not a ParaView data collection (<VTKFile type=\"Collection\">)");
  std::vector<PvdEntry> entries;
  for (int k = 0; k < collection->GetNumberOfNestedElements(); ++k) {
    vtkXMLDataElement* dataSet = collection->GetNestedElement(k);
    if (std::string(dataSet->GetName()) != "DataSet") continue;
    const char* file = dataSet->GetAttribute("file");
    if (!file || !*file)
      throw std::runtime_error(pvd.string() + ": DataSet " + std::to_string(k) +
                               " has no file attribute");
    PvdEntry entry;
    entry.file = file;
    double time = 0.0;
    entry.time = dataSet->GetScalarAttribute("timestep", time) ? time : 0.0;
    entries.push_back(entry);
  }
  return entries;
}

FrameChoice chooseFrame(const fs::path& run, const std::string& frame) {
  if (!fs::exists(run))
    throw std::runtime_error(run.string() +
                             " does not exist; expected a tlsph output directory, a .pvd, or a "
                             ".vtu or .pvtu frame");
  fs::path series = run;
  if (fs::is_directory(run)) {
    series = seriesOfDirectory(run);
  } else if (lowerExtension(run) == ".vtu" || lowerExtension(run) == ".pvtu") {
    if (!frame.empty() && frame != "last")
      throw std::runtime_error("--frame " + frame + " selects a frame of a .pvd series, but " +
                               run.string() + " is a single frame");
    FrameChoice choice;
    choice.file = run;
    return choice;
  } else if (lowerExtension(run) != ".pvd") {
    throw std::runtime_error(run.string() +
                             ": expected a tlsph output directory, a .pvd, or a .vtu or .pvtu "
                             "frame");
  }

  const std::vector<PvdEntry> entries = readPvdFile(series);
  if (entries.empty()) throw std::runtime_error(series.string() + " lists no frames");
  FrameChoice choice;
  choice.series = series;
  choice.count = entries.size();
  choice.index = entries.size() - 1;
  if (!frame.empty() && frame != "last") {
    std::size_t used = 0;
    unsigned long n = 0;
    try {
      if (!std::isdigit(static_cast<unsigned char>(frame[0]))) throw std::invalid_argument(frame);
      n = std::stoul(frame, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != frame.size() || frame.empty())
      throw std::runtime_error("--frame " + frame + ": expected 'last' or a frame number 0.." +
                               std::to_string(entries.size() - 1) + " of " + series.string());
    if (n >= entries.size())
      throw std::runtime_error("--frame " + frame + ": " + series.string() + " has " +
                               std::to_string(entries.size()) + " frames, numbered 0.." +
                               std::to_string(entries.size() - 1));
    choice.index = n;
  }
  const PvdEntry& entry = entries[choice.index];
  choice.time = entry.time;
  choice.file = entry.file.is_absolute() ? entry.file : series.parent_path() / entry.file;
  return choice;
}

}  // namespace tlsph
