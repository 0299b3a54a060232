// libFuzzer: the OBJ level loader (tinyobjloader behind Cairn's own line checks).

#include "FuzzInputFile.h"
#include "cairn/navmesh/LevelMesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* inData, size_t inSize)
{
    const std::string path = cairn::fuzz::WriteInputFile(inData, inSize, ".obj");
    (void)cairn::navmesh::LoadObjMesh(path);
    return 0;
}
