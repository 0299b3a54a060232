#include "cairn/physics/body/Layers.h"

#include <cassert>

namespace cairn
{

LayerSetup::LayerSetup(uint32_t inNumObjectLayers, uint32_t inNumBroadPhaseLayers)
    : mNumObjectLayers(inNumObjectLayers), mNumBroadPhaseLayers(inNumBroadPhaseLayers)
{
    assert(inNumObjectLayers > 0 && inNumObjectLayers <= cMaxObjectLayers);
    assert(inNumBroadPhaseLayers > 0 && inNumBroadPhaseLayers <= cMaxBroadPhaseLayers);
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
    assert(inLayer < mNumObjectLayers && inBroadPhaseLayer < mNumBroadPhaseLayers);
    mBroadPhaseLayer[inLayer] = inBroadPhaseLayer;
}

void LayerSetup::SetCollides(ObjectLayer inA, ObjectLayer inB, bool inCollides)
{
    assert(inA < mNumObjectLayers && inB < mNumObjectLayers);
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

} // namespace cairn
