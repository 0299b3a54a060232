#pragma once

// MachineInfo: one line naming the machine a benchmark ran on (CPU model, hardware threads, L2 per core), so
// that printed figures can be told apart when the project's machine changes (the same binary runs tens of per
// cent faster on one VM than another). Linux's /proc/cpuinfo and sysfs; "unknown" parts elsewhere. Main thread.

#include <fstream>
#include <string>
#include <thread>

namespace cairn::tools
{

/// "CPU <model>, <n> hardware threads, L2 <size> a core".
inline std::string DescribeMachine()
{
    std::string model = "unknown";
    std::ifstream cpuInfo("/proc/cpuinfo");
    for (std::string line; std::getline(cpuInfo, line);)
        if (line.rfind("model name", 0) == 0)
        {
            const size_t colon = line.find(':');
            if (colon != std::string::npos && colon + 2 <= line.size()) model = line.substr(colon + 2);
            break;
        }
    std::string l2 = "unknown";
    std::ifstream l2Size("/sys/devices/system/cpu/cpu0/cache/index2/size");
    if (std::string size; l2Size >> size) l2 = size;
    return "CPU " + model + ", " + std::to_string(std::thread::hardware_concurrency()) +
           " hardware threads, L2 " + l2 + " a core";
}

} // namespace cairn::tools
