// Machine description: /proc/cpuinfo for the CPU, and an Embree device created
// once with "verbose=1" while stdout is redirected to a temporary file, so the
// ISA and tasking lines are Embree's own words, not a guess.
#include "bench/report/machine_info.h"

#include <embree3/rtcore.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <mutex>
#include <set>
#include <sstream>

namespace hprt::bench {
namespace {

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

void read_cpuinfo(MachineInfo& m) {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  std::set<std::string> flags;
  while (std::getline(in, line)) {
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = trim(line.substr(0, colon));
    if (key == "model name" && m.cpu_model.empty()) m.cpu_model = trim(line.substr(colon + 1));
    if (key == "flags" && flags.empty()) {
      std::istringstream words(line.substr(colon + 1));
      std::string w;
      while (words >> w) flags.insert(w);
    }
  }
  if (m.cpu_model.empty()) m.cpu_model = "unknown";
  for (const char* f : {"sse4_2", "avx", "avx2", "fma", "avx512f", "avx512dq", "avx512bw",
                        "avx512vl", "neon", "asimd"})
    if (flags.count(f)) m.isa_flags.push_back(f);
}

// Runs rtcNewDevice("verbose=1") with fd 1 pointing at a temporary file and
// returns what Embree printed.
std::string embree_banner(RTCDevice* device_out) {
  std::cout.flush();
  std::fflush(stdout);
  FILE* tmp = std::tmpfile();
  const int saved = tmp ? ::dup(STDOUT_FILENO) : -1;
  if (saved >= 0) ::dup2(::fileno(tmp), STDOUT_FILENO);
  *device_out = rtcNewDevice("verbose=1");
  std::cout.flush();
  std::fflush(stdout);
  std::string text;
  if (saved >= 0) {
    ::dup2(saved, STDOUT_FILENO);
    ::close(saved);
    std::rewind(tmp);
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, tmp)) > 0) text.append(buf, n);
  }
  if (tmp) std::fclose(tmp);
  return text;
}

// Value after "<key> :" on the first line (after `after`) that starts with `key`.
std::string banner_value(const std::string& banner, const std::string& key, size_t after = 0) {
  std::istringstream in(banner.substr(std::min(after, banner.size())));
  std::string line;
  while (std::getline(in, line)) {
    const std::string t = trim(line);
    if (t.rfind(key, 0) == 0) {
      const size_t colon = t.find(':');
      if (colon != std::string::npos) return trim(t.substr(colon + 1));
    }
  }
  return "";
}

void probe_embree(MachineInfo& m) {
  RTCDevice device = nullptr;
  const std::string banner = embree_banner(&device);
  if (!device) {
    m.embree_version = "unavailable";
    return;
  }
  const ssize_t v = rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION);
  m.embree_version = std::to_string(v / 10000) + "." + std::to_string(v / 100 % 100) + "." +
                     std::to_string(v % 100);
  const ssize_t tasking = rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_TASKING_SYSTEM);
  const char* names[] = {"internal", "TBB", "PPL"};
  m.embree_tasking = tasking >= 0 && tasking <= 2 ? names[tasking] : "unknown";
  const size_t config = banner.find("Config");
  const std::string tasking_line = banner_value(banner, "Tasking", config);
  if (!tasking_line.empty()) m.embree_tasking += " (" + tasking_line + ")";
  // "Targets : SSE ... AVX512  (supported)" then the compile-time line.
  std::string targets = banner_value(banner, "Targets", config);
  const size_t sup = targets.find("(supported)");
  if (sup != std::string::npos) targets = trim(targets.substr(0, sup));
  m.embree_targets = targets;
  const size_t cpos = banner.find("(compile time enabled)");
  if (cpos != std::string::npos) {
    const size_t line_start = banner.rfind('\n', cpos);
    m.embree_compiled = trim(banner.substr(line_start + 1, cpos - line_start - 1));
  }
  // Widest target Embree will dispatch to: compiled in and supported by the CPU.
  const std::string padded_t = " " + m.embree_targets + " ";
  const std::string padded_c = " " + m.embree_compiled + " ";
  for (const char* isa : {"AVX512", "AVX2", "AVX", "SSE4.2", "SSE2"}) {
    const std::string w = std::string(" ") + isa + " ";
    if (padded_t.find(w) != std::string::npos &&
        (m.embree_compiled.empty() || padded_c.find(w) != std::string::npos)) {
      m.embree_isa = isa;
      break;
    }
  }
  if (m.embree_isa.empty()) m.embree_isa = "unknown";
  // Native packet widths Embree reports (4 = SSE, 8 = AVX, 16 = AVX-512).
  std::string widths;
  for (auto [prop, w] : {std::pair{RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED, "4"},
                         std::pair{RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED, "8"},
                         std::pair{RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED, "16"}})
    if (rtcGetDeviceProperty(device, prop) == 1)
      widths += std::string(widths.empty() ? "" : "/") + w;
  if (!widths.empty()) m.embree_isa += " (native ray packets " + widths + ")";
  rtcReleaseDevice(device);
}

}  // namespace

const MachineInfo& machine_info() {
  static MachineInfo info;
  static std::once_flag once;
  std::call_once(once, [] {
    read_cpuinfo(info);
    info.logical_cores = tbb::this_task_arena::max_concurrency();
    probe_embree(info);
#if defined(__clang__)
    info.compiler = "clang " __clang_version__;
#elif defined(__GNUC__)
    info.compiler = "g++ " __VERSION__;
#else
    info.compiler = "unknown";
#endif
  });
  return info;
}

nlohmann::json to_json(const MachineInfo& m) {
  return {{"cpu_model", m.cpu_model},
          {"isa_flags", m.isa_flags},
          {"logical_cores", m.logical_cores},
          {"embree_version", m.embree_version},
          {"embree_isa", m.embree_isa},
          {"embree_targets", m.embree_targets},
          {"embree_compiled", m.embree_compiled},
          {"embree_tasking", m.embree_tasking},
          {"compiler", m.compiler}};
}

std::string machine_markdown(const MachineInfo& m) {
  std::string flags;
  for (const auto& f : m.isa_flags) flags += (flags.empty() ? "" : " ") + f;
  return "- CPU: " + m.cpu_model + " (" + std::to_string(m.logical_cores) +
         " logical cores), ISA flags: " + (flags.empty() ? "none detected" : flags) +
         "\n- Embree " + m.embree_version + ", ISA " + m.embree_isa + ", tasking " +
         m.embree_tasking + "\n- Compiler: " + m.compiler + "\n";
}

}  // namespace hprt::bench
