// libFuzzer: the baker's JSON readers, the agent profile config, the material area mapping and the off-mesh
// links, on each input.

#include "BakeConfig.h"
#include "FuzzInputFile.h"
#include "OffMeshLinksFile.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* inData, size_t inSize)
{
    const std::string path = cairn::fuzz::WriteInputFile(inData, inSize, ".json");
    cairn::navmesh::AgentProfile profile;
    (void)cairn::bake::LoadBakeConfig(path, profile);
    (void)cairn::bake::LoadAreaMapping(path);
    (void)cairn::bake::LoadOffMeshLinks(path);
    return 0;
}
