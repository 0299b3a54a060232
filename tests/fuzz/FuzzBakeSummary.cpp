// libFuzzer: the bake summary reader (the previous bake's JSON of an incremental bake).

#include "BakeSummary.h"
#include "FuzzInputFile.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* inData, size_t inSize)
{
    const std::string path = cairn::fuzz::WriteInputFile(inData, inSize, ".json");
    (void)cairn::bake::LoadBakeSummary(path);
    return 0;
}
