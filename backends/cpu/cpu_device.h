// cpu_device.h — the CPU reference backend: buffers in host memory, each
// dispatch run in parallel with TBB.
#pragma once

#include <memory>

#include "backends/backend.h"

namespace sinew {

/// [in] options.threads: worker threads (0 = all hardware threads, else >= 1).
Result<std::unique_ptr<Device>> make_cpu_device(const DeviceOptions& options);

}  // namespace sinew
