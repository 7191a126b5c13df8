#pragma once
// Logging through spdlog: one process-wide logger writing to stderr. Library code logs warnings
// about recoverable problems (a skipped frame); errors travel as Status, not as log lines.

#include <spdlog/spdlog.h>

namespace gvkit {

enum class LogLevel { kDebug, kInfo, kWarn, kError, kOff };

void set_log_level(LogLevel level);
// The shared logger ("gvkit"), created on first use.
spdlog::logger& logger();

}  // namespace gvkit
