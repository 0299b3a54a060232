// A program outside Cairn's tree that finds the installed package and links cairn::physics: a dropped sphere
// falls under gravity. Prints the height after one second so the test can check the library really ran.
#include <cairn/physics/PhysicsSystem.h>
#include <cairn/physics/shapes/SphereShape.h>
#include <cstdio>

int main()
{
    cairn::PhysicsSystem system;
    cairn::BodyCreationSettings settings;
    settings.mShape = cairn::SphereShape::Create(1.0f).Value();
    settings.mPosition = cairn::Vec3(0, 10, 0);
    const cairn::BodyID id =
        system.GetBodyInterface().CreateAndAddBody(settings, cairn::Activation::Activate).Value();
    for (int i = 0; i < 60; ++i)
        (void)system.Update(1.0f / 60.0f);
    std::printf("height after 1 s: %.2f\n", system.GetBodyInterface().GetPosition(id).Value().y());
    return 0;
}
