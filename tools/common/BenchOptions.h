#pragma once

// BenchOptions: the command line the tools' own benchmark programs share (cairn-bench-step, -navmesh, -bake):
// --repetitions N, --only NAME and, for some, --threads 1,2. Read with CLI11 (Debian's libcli11-dev), so a
// malformed value is an error with a message rather than a silent default. Main thread, at start-up.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cairn::tools
{
using namespace cairn::physics;

struct BenchOptions
{
    int mRepetitions = 3;
    std::string mOnly;                    ///< One benchmark's name, or empty for all
    std::vector<uint32_t> mThreads{1, 2}; ///< Thread counts, where the program takes --threads
};

/// Fills ioOptions from the command line. inBenchmarks: the names --only accepts. Returns the exit code to
/// stop with (0 after --help, 2 on a usage error, the message printed), or nothing to go on.
inline std::optional<int> ParseBenchOptions(int inArgc, char** inArgv, const std::string& inDescription,
                                            const std::vector<std::string>& inBenchmarks,
                                            BenchOptions& ioOptions, bool inTakesThreads = false,
                                            const std::function<void(CLI::App&)>& inMoreOptions = {})
{
    CLI::App app{inDescription};
    if (inMoreOptions) inMoreOptions(app);
    app.add_option("--repetitions", ioOptions.mRepetitions, "Runs of each benchmark (medians are printed)")
        ->check(CLI::Range(1, 1000));
    app.add_option("--only", ioOptions.mOnly, "Run one benchmark")->check(CLI::IsMember(inBenchmarks));
    if (inTakesThreads)
        app.add_option("--threads", ioOptions.mThreads, "Thread counts, comma-separated")
            ->delimiter(',')
            ->check(CLI::Range(1, 64));
    try
    {
        app.parse(inArgc, inArgv);
    }
    catch (const CLI::ParseError& error)
    {
        return app.exit(error) == 0 ? 0 : 2;
    }
    return std::nullopt;
}

} // namespace cairn::tools
