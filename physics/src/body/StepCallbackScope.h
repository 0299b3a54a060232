#pragma once

// StepCallbackScope: a game callback that the step runs on one of its job threads (a ContactListener's
// OnContactValidate, OnContactAdded, OnContactPersisted) counts as inside the step
// (BodyManager::IsInsideStep) while it runs. The step holds every body lock from the updating thread; a
// BodyInterface, ConstraintInterface, PhysicsSystem or locking WorldQuery call from the callback then returns
// WrongThread where it would wait on those locks for ever. Lives on the job thread's stack, for one callback;
// nests.

namespace cairn::physics
{

class StepCallbackScope
{
public:
    StepCallbackScope();
    ~StepCallbackScope();
    StepCallbackScope(const StepCallbackScope&) = delete;
    StepCallbackScope& operator=(const StepCallbackScope&) = delete;

private:
    bool mWasInside; ///< This thread's flag before: the updating thread runs callbacks too, already inside
};

} // namespace cairn::physics
