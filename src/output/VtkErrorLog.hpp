// VTK's error messages collected for an exception instead of printed: VTK readers report most
// failures only as messages (the XML readers' error code stays 0), so the messages are the
// only way to say why a file could not be read.
#pragma once

#include <vtkCallbackCommand.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkWeakPointer.h>

#include <string>

namespace tlsph {

class VtkErrorLog {
 public:
  // Collects the error messages of `source` (a reader or parser). For an algorithm, the
  // pipeline's generic "algorithm returned failure" is dropped: the reader's own message says
  // why. While the log lives VTK prints nothing (output window and vtkLogger's stderr sink),
  // so helper objects the reader creates (the XML parser) do not print to stderr either.
  explicit VtkErrorLog(vtkObject* source);
  ~VtkErrorLog();
  VtkErrorLog(const VtkErrorLog&) = delete;
  VtkErrorLog& operator=(const VtkErrorLog&) = delete;

  bool empty() const { return text_.empty(); }
  // The messages joined by "; ", without VTK's "ERROR: In <source file>, line N" prefixes.
  const std::string& text() const { return text_; }

 private:
  static void append(vtkObject*, unsigned long, void* clientData, void* callData);

  std::string text_;
  int displayMode_;
  int logVerbosity_;
  vtkWeakPointer<vtkObject> source_, executive_;
  unsigned long sourceTag_ = 0, executiveTag_ = 0;
  vtkNew<vtkCallbackCommand> onError_;
  vtkNew<vtkCallbackCommand> ignore_;
};

}  // namespace tlsph
