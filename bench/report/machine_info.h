// What a benchmark ran on: CPU model and ISA flags (/proc/cpuinfo), logical
// cores, and Embree's version, ISA targets and tasking system as Embree itself
// reports them (rtcGetDeviceProperty and the device's verbose banner).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace hprt::bench {

struct MachineInfo {
  std::string cpu_model;               // "model name" of /proc/cpuinfo
  std::vector<std::string> isa_flags;  // the SIMD flags present, e.g. avx2 avx512f
  int logical_cores = 0;               // hardware threads TBB sees
  std::string embree_version;          // "3.13.5" from RTC_DEVICE_PROPERTY_VERSION
  std::string embree_isa;              // widest target both compiled in and supported
  std::string embree_targets;          // Embree's "Targets" line (supported by the CPU)
  std::string embree_compiled;         // Embree's compile-time enabled targets
  std::string embree_tasking;          // RTC_DEVICE_PROPERTY_TASKING_SYSTEM + banner
  std::string compiler;                // compiler hprt was built with
};

// Probed once per process (creates and releases one Embree device).
const MachineInfo& machine_info();

nlohmann::json to_json(const MachineInfo& m);
// Markdown bullet lines ("- CPU: ...") for the header of a bench report.
std::string machine_markdown(const MachineInfo& m);

}  // namespace hprt::bench
