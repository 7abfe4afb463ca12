#include "output/VtkErrorLog.hpp"

#include <vtkAlgorithm.h>
#include <vtkCommand.h>
#include <vtkExecutive.h>
#include <vtkLogger.h>
#include <vtkOutputWindow.h>

#include <cctype>

namespace tlsph {

VtkErrorLog::VtkErrorLog(vtkObject* source)
    : displayMode_(vtkOutputWindow::GetInstance()->GetDisplayMode()),
      logVerbosity_(vtkLogger::GetCurrentVerbosityCutoff()) {
  // Unobserved objects' errors go to the output window and to vtkLogger's stderr sink.
  vtkOutputWindow::GetInstance()->SetDisplayModeToNever();
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  onError_->SetCallback(&VtkErrorLog::append);
  onError_->SetClientData(&text_);
  source_ = source;
  sourceTag_ = source->AddObserver(vtkCommand::ErrorEvent, onError_);
  if (auto* algorithm = vtkAlgorithm::SafeDownCast(source)) {
    executive_ = algorithm->GetExecutive();
    executiveTag_ = executive_->AddObserver(vtkCommand::ErrorEvent, ignore_);
  }
}

VtkErrorLog::~VtkErrorLog() {
  // The observers point at this log: detach them from objects that may outlive it.
  if (source_) source_->RemoveObserver(sourceTag_);
  if (executive_) executive_->RemoveObserver(executiveTag_);
  vtkOutputWindow::GetInstance()->SetDisplayMode(displayMode_);
  vtkLogger::SetStderrVerbosity(static_cast<vtkLogger::Verbosity>(logVerbosity_));
}

void VtkErrorLog::append(vtkObject*, unsigned long, void* clientData, void* callData) {
  auto& text = *static_cast<std::string*>(clientData);
  std::string message = callData ? static_cast<const char*>(callData) : "";
  // VTK prefixes "ERROR: In <source file>, line N\n<class> (<address>): ".
  if (const auto eol = message.find('\n'); eol != std::string::npos) message.erase(0, eol + 1);
  if (const auto colon = message.find("): "); colon != std::string::npos && colon < 80)
    message.erase(0, colon + 3);
  while (!message.empty() && std::isspace(static_cast<unsigned char>(message.back())))
    message.pop_back();
  // Some readers report the same failure twice.
  if (message.empty() || text == message ||
      (text.size() > message.size() && text.ends_with("; " + message)))
    return;
  if (!text.empty()) text += "; ";
  text += message;
}

}  // namespace tlsph
