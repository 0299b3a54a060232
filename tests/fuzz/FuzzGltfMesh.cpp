// libFuzzer: the glTF level loader, as .glb when the input starts with the binary magic, else as .gltf.

#include "FuzzInputFile.h"
#include "cairn/navmesh/LevelMesh.h"

#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* inData, size_t inSize)
{
    const bool binary = inSize >= 4 && std::memcmp(inData, "glTF", 4) == 0;
    const std::string path = cairn::fuzz::WriteInputFile(inData, inSize, binary ? ".glb" : ".gltf");
    (void)cairn::navmesh::LoadGltfMesh(path);
    return 0;
}
