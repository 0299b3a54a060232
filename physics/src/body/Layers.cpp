#include "cairn/physics/body/Layers.h"

#include <algorithm>

namespace cairn::physics
{

LayerSetup::LayerSetup(uint32_t inNumObjectLayers, uint32_t inNumBroadPhaseLayers)
    : mNumObjectLayers(std::clamp(inNumObjectLayers, 1u, cMaxObjectLayers)),
      mNumBroadPhaseLayers(std::clamp(inNumBroadPhaseLayers, 1u, cMaxBroadPhaseLayers))
{
    if (mNumObjectLayers != inNumObjectLayers)
        RecordError("the number of object layers must be in 1.." + std::to_string(cMaxObjectLayers) +
                    ", not " + std::to_string(inNumObjectLayers));
    if (mNumBroadPhaseLayers != inNumBroadPhaseLayers)
        RecordError("the number of broad-phase layers must be in 1.." + std::to_string(cMaxBroadPhaseLayers) +
                    ", not " + std::to_string(inNumBroadPhaseLayers));
}

void LayerSetup::RecordError(std::string inMessage)
{
    if (mError.empty()) mError = "layer setup: " + std::move(inMessage);
}

Status LayerSetup::GetStatus() const
{
    if (mError.empty()) return Status::Ok();
    return MakeError(ErrorCode::InvalidArgument, mError);
}

LayerSetup LayerSetup::CreateDefault()
{
    LayerSetup setup(4, 2);
    setup.SetBroadPhaseLayer(Layers::cStatic, BroadPhaseLayers::cStatic);
    setup.SetBroadPhaseLayer(Layers::cMoving, BroadPhaseLayers::cMoving);
    setup.SetBroadPhaseLayer(Layers::cDebris, BroadPhaseLayers::cMoving);
    setup.SetBroadPhaseLayer(Layers::cTrigger, BroadPhaseLayers::cMoving);
    setup.SetCollides(Layers::cStatic, Layers::cMoving, true);
    setup.SetCollides(Layers::cStatic, Layers::cDebris, true);
    setup.SetCollides(Layers::cMoving, Layers::cMoving, true);
    return setup;
}

void LayerSetup::SetBroadPhaseLayer(ObjectLayer inLayer, BroadPhaseLayer inBroadPhaseLayer)
{
    if (inLayer >= mNumObjectLayers || inBroadPhaseLayer >= mNumBroadPhaseLayers)
    {
        RecordError("SetBroadPhaseLayer(" + std::to_string(inLayer) + ", " +
                    std::to_string(inBroadPhaseLayer) + ") is out of range (" +
                    std::to_string(mNumObjectLayers) + " object layers, " +
                    std::to_string(mNumBroadPhaseLayers) + " broad-phase layers)");
        return;
    }
    mBroadPhaseLayer[inLayer] = inBroadPhaseLayer;
}

void LayerSetup::SetCollides(ObjectLayer inA, ObjectLayer inB, bool inCollides)
{
    if (inA >= mNumObjectLayers || inB >= mNumObjectLayers)
    {
        RecordError("SetCollides(" + std::to_string(inA) + ", " + std::to_string(inB) +
                    ") is out of range (" + std::to_string(mNumObjectLayers) + " object layers)");
        return;
    }
    const ObjectLayerMask bitA = ObjectLayerMask(1) << inA;
    const ObjectLayerMask bitB = ObjectLayerMask(1) << inB;
    if (inCollides)
    {
        mCollidesWith[inA] |= bitB;
        mCollidesWith[inB] |= bitA;
    }
    else
    {
        mCollidesWith[inA] &= ~bitB;
        mCollidesWith[inB] &= ~bitA;
    }
}

ObjectLayerMask LayerSetup::GetObjectLayersIn(BroadPhaseLayer inLayer) const
{
    ObjectLayerMask mask = 0;
    for (uint32_t layer = 0; layer < mNumObjectLayers; ++layer)
        if (mBroadPhaseLayer[layer] == inLayer) mask |= ObjectLayerMask(1) << layer;
    return mask;
}

} // namespace cairn::physics
