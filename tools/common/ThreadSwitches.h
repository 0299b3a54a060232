#pragma once

// Whether another task took a thread's core: Linux counts, per thread, the times the scheduler switched it
// out while it could still run (nonvoluntary_ctxt_switches in /proc/self/task/<tid>/status). Any thread may
// read any thread's count. A window in which the frame's threads had none ran on its cores alone; with one,
// a kernel thread or another process had a core for a while, and the window's wall time holds that while.

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <dirent.h>
#include <string>
#include <string_view>
#include <sys/syscall.h>
#include <unistd.h>
#include <vector>

namespace cairn::tools
{

/// The calling thread's id, as /proc/self/task names it (-1 where there is no such thing).
inline int CurrentThreadId()
{
#if defined(__linux__)
    return int(syscall(SYS_gettid));
#else
    return -1;
#endif
}

/// The ids of this process's threads whose name begins with inPrefix (empty where they can not be listed).
inline std::vector<int> FindThreadsNamed(std::string_view inPrefix)
{
    std::vector<int> ids;
    DIR* tasks = opendir("/proc/self/task");
    if (tasks == nullptr) return ids;
    while (const dirent* entry = readdir(tasks))
    {
        if (entry->d_name[0] < '0' || entry->d_name[0] > '9') continue; // "." and ".."
        const std::string path = std::string("/proc/self/task/") + entry->d_name + "/comm";
        FILE* file = std::fopen(path.c_str(), "r");
        if (file == nullptr) continue; // The thread ended meanwhile
        char name[64] = {};
        const bool read = std::fgets(name, sizeof(name), file) != nullptr;
        std::fclose(file);
        if (read && std::string_view(name).substr(0, inPrefix.size()) == inPrefix)
            ids.push_back(std::atoi(entry->d_name));
    }
    closedir(tasks);
    return ids;
}

/// Times the thread was switched out while it could still run; -1 when that can not be read.
inline int64_t InvoluntarySwitches(int inThreadId)
{
    const std::string path = "/proc/self/task/" + std::to_string(inThreadId) + "/status";
    FILE* file = std::fopen(path.c_str(), "r");
    if (file == nullptr) return -1;
    constexpr const char* cField = "nonvoluntary_ctxt_switches:";
    char line[256];
    int64_t switches = -1;
    while (std::fgets(line, sizeof(line), file) != nullptr)
        if (std::strncmp(line, cField, std::strlen(cField)) == 0)
        {
            switches = std::strtoll(line + std::strlen(cField), nullptr, 10);
            break;
        }
    std::fclose(file);
    return switches;
}

/// The summed count of inThreadIds; -1 when any can not be read.
inline int64_t InvoluntarySwitches(const std::vector<int>& inThreadIds)
{
    int64_t total = 0;
    for (int id : inThreadIds)
    {
        const int64_t switches = InvoluntarySwitches(id);
        if (switches < 0) return -1;
        total += switches;
    }
    return total;
}

} // namespace cairn::tools
