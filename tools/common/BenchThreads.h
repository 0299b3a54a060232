#pragma once

// Thread counts for the benchmarks that sweep them, from an environment variable ("1,2,4,8,16"), so that the
// 16-core run (tools/manycore/run.sh) asks for more than a 2-core default without another build. A malformed
// list is reported and the default kept.

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace cairn::tools
{

inline std::vector<int> BenchThreadCounts(const char* inVariable, std::vector<int> inDefault)
{
    const char* text = std::getenv(inVariable);
    if (text == nullptr || text[0] == '\0') return inDefault;
    std::vector<int> counts;
    const std::string list(text);
    for (size_t start = 0; start <= list.size();)
    {
        const size_t comma = std::min(list.find(',', start), list.size());
        int count = 0;
        const auto [end, error] = std::from_chars(list.data() + start, list.data() + comma, count);
        if (error != std::errc() || end != list.data() + comma || count < 1 || count > 256)
        {
            std::fprintf(stderr,
                         "%s=%s: expected thread counts from 1 to 256, comma-separated; using the default\n",
                         inVariable, text);
            return inDefault;
        }
        counts.push_back(count);
        start = comma + 1;
    }
    return counts;
}

} // namespace cairn::tools
