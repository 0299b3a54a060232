#pragma once

// ConstraintInterface: joints between two bodies, or a body and the world (issue 33). A joint links its
// bodies into one simulation island, as a contact does: they are solved together, sleep together and wake
// together. Solved in the same sequential-impulse passes as the contacts (velocity rows warm-started from the
// last step's impulse, drift taken out on the poses after integration).
//
// Joints: fixed (welded), point (ball and socket), distance (rod, rope, spring), hinge and slider (each with
// limits, a velocity or position motor and friction) and swing-twist (a cone and a twist range, for
// ragdolls). A large island (a quarter of the step's contacts and joints) is colored, its joints with its
// contacts, and solved by every thread a color at a time; a smaller island with a joint is solved whole by
// one thread. The same result for any thread count either way.
//
// Threads: every method from any thread, outside the physics step's callbacks and while holding no body lock
// (WrongThread otherwise). A call made while Update runs waits for the step to end (the step holds the
// joints' mutex, as it holds every body mutex). A joint whose body is gone or not in the world does nothing
// until it is (a stale body id never reaches another body: ids carry their sequence).

#include "cairn/physics/body/BodyID.h"
#include "cairn/physics/math/Math.h"
#include "cairn/physics/math/Result.h"

#include <cstdint>
#include <numbers>
#include <vector>

namespace cairn::physics
{

class BodyManager;
class ConstraintManager;
struct Joint;

/// A joint, as Add returns it: its slot and that slot's generation (a removed joint's id goes stale).
class ConstraintID
{
public:
    static constexpr uint32_t cInvalidIndex = 0xffffffffu;
    constexpr ConstraintID() = default;
    constexpr ConstraintID(uint32_t inIndex, uint32_t inSequence) : mIndex(inIndex), mSequence(inSequence) {}
    constexpr uint32_t GetIndex() const { return mIndex; }
    constexpr uint32_t GetSequence() const { return mSequence; }
    constexpr bool IsInvalid() const { return mIndex == cInvalidIndex; }
    constexpr auto operator<=>(const ConstraintID&) const = default;

private:
    uint32_t mIndex = cInvalidIndex;
    uint32_t mSequence = 0;
};

/// A ball and socket: a point of A stays on a point of B, any rotation free.
struct PointConstraintSettings
{
    BodyID mBodyA; ///< An invalid id: the world
    BodyID mBodyB; ///< Likewise; at most one side is the world, and the two are different bodies
    /// The joint's point in world space, at creation: each body keeps the point where it is on it now
    Vec3 mPoint = Vec3::Zero();
};

/// Welds B to A: a point of each stays together and B keeps its rotation relative to A's as at creation.
struct FixedConstraintSettings
{
    BodyID mBodyA; ///< An invalid id: the world
    BodyID mBodyB;
    Vec3 mPoint = Vec3::Zero(); ///< World space, at creation: where the two are held together
};

/// What a joint's motor does.
enum class MotorMode : uint8_t
{
    Off,      ///< Nothing (the joint's friction acts instead)
    Velocity, ///< Drives the relative spin (or speed) to a target, within its largest torque (or force)
    Position, ///< Pulls the angle (or place) to a target as a spring would, within its largest torque (force)
};

/// A spring that softens a joint's row: the implicit Euler step of a spring and damper on the row's effective
/// mass, so its frequency does not depend on the bodies' masses.
struct SpringSettings
{
    float mFrequency = 0.0f; ///< Hz; 0: rigid
    float mDamping = 0.0f;   ///< Ratio to critical damping (1: critical)
};

/// A hinge's or a slider's motor: rad, rad/s and N m for a hinge; m, m/s and N for a slider. B's motion
/// relative to A's, measured as the joint's limits are.
struct MotorSettings
{
    MotorMode mMode = MotorMode::Off;
    float mTargetVelocity = 0.0f; ///< Velocity mode
    float mTargetPosition = 0.0f; ///< Position mode: an angle within [-pi, pi] for a hinge
    float mMaxForce = 0.0f;       ///< The most it drives with, torque or force (0: it does nothing)
    /// Position mode: how it pulls; a frequency above 0 (a door: 1-4 Hz), damping 1 stops without overshoot
    SpringSettings mSpring{2.0f, 1.0f};
};

/// A door, a wheel: B turns about an axis through a point of A, within limits, driven by a motor or held by
/// friction.
struct HingeConstraintSettings
{
    BodyID mBodyA; ///< An invalid id: the world
    BodyID mBodyB;
    Vec3 mPoint = Vec3::Zero();               ///< World space, at creation: a point of the axis
    Vec3 mHingeAxis = Vec3(0.0f, 1.0f, 0.0f); ///< World space, at creation (normalised)
    /// B's angle about the axis from where it is at creation (rad, right-handed, within [-pi, pi]); the
    /// whole range: no limit
    float mLimitsMin = -std::numbers::pi_v<float>;
    float mLimitsMax = std::numbers::pi_v<float>;
    float mMaxFrictionTorque = 0.0f; ///< N m, while the motor is off
    MotorSettings mMotor;            ///< rad, rad/s, N m
};

/// A drawer, a piston, a sliding gate: B moves along an axis fixed in A, within limits, driven by a motor or
/// held by friction; its rotation relative to A's is kept as at creation.
struct SliderConstraintSettings
{
    BodyID mBodyA; ///< An invalid id: the world
    BodyID mBodyB;
    Vec3 mPoint = Vec3::Zero();                ///< World space, at creation: a point of the axis
    Vec3 mSliderAxis = Vec3(1.0f, 0.0f, 0.0f); ///< World space, at creation (normalised)
    /// B's place along the axis from where it is at creation (m); the defaults: no limit
    float mLimitsMin = -cLargeFloat;
    float mLimitsMax = cLargeFloat;
    float mMaxFrictionForce = 0.0f; ///< N, while the motor is off
    MotorSettings mMotor;           ///< m, m/s, N
};

/// A shoulder, a hip, a neck: a ball and socket whose swing is limited to an elliptic cone round the twist
/// axis and whose twist about that axis is limited to a range (a ragdoll's joints; Jolt's SwingTwist, PhysX's
/// D6 with swing and twist limits). The angles are B's frame relative to A's from where they are at creation:
/// the twist axis, the plane axis across it and the normal axis (twist x plane) make the frame.
struct SwingTwistConstraintSettings
{
    BodyID mBodyA; ///< An invalid id: the world
    BodyID mBodyB;
    Vec3 mPoint = Vec3::Zero();               ///< World space, at creation: the socket
    Vec3 mTwistAxis = Vec3(1.0f, 0.0f, 0.0f); ///< World space, at creation: along the limb, A to B
    Vec3 mPlaneAxis = Vec3(0.0f, 1.0f, 0.0f); ///< World space, at creation, perpendicular to the twist axis
    /// How far the twist axis may tilt towards the normal axis (a turn about the plane axis), and within the
    /// twist and plane axes' plane (a turn about the normal axis), rad in [0, pi]
    float mNormalHalfConeAngle = 0.0f;
    float mPlaneHalfConeAngle = 0.0f;
    float mTwistMinAngle = 0.0f; ///< rad, within [-pi, pi], min <= max
    float mTwistMaxAngle = 0.0f;
    float mMaxFrictionTorque = 0.0f; ///< N m about each of the frame's axes: a limb that settles, not jitters
};

/// Keeps the distance between a point of A and a point of B within [min, max]: equal, a rod; min 0, a rope;
/// with a spring, the limits give like a spring (equal limits: a spring of that rest length).
struct DistanceConstraintSettings
{
    BodyID mBodyA; ///< An invalid id: the world
    BodyID mBodyB;
    Vec3 mPointA = Vec3::Zero(); ///< World space, at creation (each body keeps its point where it is on it)
    Vec3 mPointB = Vec3::Zero();
    float mMinDistance = -1.0f; ///< m; negative: the distance between the points now
    float mMaxDistance = -1.0f; ///< m; negative: the distance between the points now
    SpringSettings mLimitsSpring;
};

/// A joint that broke: the force and torque it held in the step it broke in (N, N m).
struct BrokenConstraint
{
    ConstraintID mID;
    float mForce = 0.0f;
    float mTorque = 0.0f;
};

class ConstraintInterface
{
public:
    /// At most this many joints at once: a bad count gets OutOfCapacity, not memory to match.
    static constexpr uint32_t cMaxConstraints = 1u << 20;

    ConstraintInterface(ConstraintManager& ioManager, BodyManager& ioBodies);

    /// A point joint, enabled. The dynamic bodies it joins are woken. Errors: a point that is NaN or beyond
    /// the world, both sides the world or the same body (InvalidArgument), a stale or unknown body id
    /// (InvalidBodyID), cMaxConstraints reached (OutOfCapacity), the wrong thread (WrongThread).
    Result<ConstraintID> AddPoint(const PointConstraintSettings& inSettings);
    /// A fixed joint, enabled, its bodies woken. Errors as AddPoint's.
    Result<ConstraintID> AddFixed(const FixedConstraintSettings& inSettings);
    /// A hinge joint, enabled, its bodies woken. Errors as AddPoint's, and for an axis that is zero or not
    /// finite, limits or a motor's target angle outside [-pi, pi] or with min > max, a torque below 0 or not
    /// finite, a motor's speed not finite, a position motor's spring frequency not above 0 (InvalidArgument).
    Result<ConstraintID> AddHinge(const HingeConstraintSettings& inSettings);
    /// A slider joint, enabled, its bodies woken. Errors as AddPoint's, and for an axis that is zero or not
    /// finite, limits that are NaN or with min > max, a force below 0 or not finite, a motor's target not
    /// finite, a position motor's spring frequency not above 0 (InvalidArgument).
    Result<ConstraintID> AddSlider(const SliderConstraintSettings& inSettings);
    /// A swing-twist joint, enabled, its bodies woken. Errors as AddPoint's, and for axes that are zero, not
    /// finite or not perpendicular, half angles outside [0, pi], twist limits outside [-pi, pi] or with min >
    /// max, a torque below 0 or not finite (InvalidArgument).
    Result<ConstraintID> AddSwingTwist(const SwingTwistConstraintSettings& inSettings);
    /// A distance joint, enabled, its bodies woken. Errors as AddPoint's, and for limits that are not finite,
    /// below 0 or with min > max, or a spring's frequency or damping negative or not finite
    /// (InvalidArgument).
    Result<ConstraintID> AddDistance(const DistanceConstraintSettings& inSettings);
    /// A hinge's or slider's motor, from the next step (a door closing on a timer: Position mode, the closed
    /// angle). Its bodies are woken. Errors: a stale id, a joint of another type, or settings AddHinge or
    /// AddSlider would refuse (InvalidArgument); the wrong thread (WrongThread).
    Status SetMotor(ConstraintID inID, const MotorSettings& inMotor);
    /// A hinge's angle (rad, within [-pi, pi]) or a slider's place (m) now, as its limits measure them.
    /// Errors: a stale id or another type (InvalidArgument), a body of it gone (InvalidBodyID), WrongThread.
    Result<float> GetPosition(ConstraintID inID) const;
    /// A joint breaks when the force (or the torque) it held in a step is above these (N, N m; cLargeFloat,
    /// the default: never): at the step's end it is disabled and reported, once (TakeBrokenConstraints;
    /// enable it again to mend it). The force is its point's or line's, or a distance joint's length row's;
    /// the torque is what holds its rotation (fixed, slider) or its axis (hinge). Errors: a stale id, a
    /// threshold NaN or below 0 (InvalidArgument), WrongThread.
    Status SetBreakThresholds(ConstraintID inID, float inForce, float inTorque);
    /// The joints that broke since the last call, in the order they broke (by step, then by id's slot).
    Result<std::vector<BrokenConstraint>> TakeBrokenConstraints();
    /// Removes a joint; its id goes stale. Its bodies are woken (a body hanging from it falls).
    Status Remove(ConstraintID inID);
    /// A disabled joint does nothing and links no island; enabling starts it from no impulse. Its bodies are
    /// woken either way.
    Status SetEnabled(ConstraintID inID, bool inEnabled);
    Result<bool> IsEnabled(ConstraintID inID) const;
    /// Joints that exist (enabled or not).
    Result<uint32_t> GetNumConstraints() const;

private:
    /// Wakes the body inID if it is dynamic and in the world (a stale id or the world: nothing).
    void WakeBody(const BodyID& inID);
    /// The checks every joint needs, its anchors from the world points, then the joint stored and its bodies
    /// woken.
    Result<ConstraintID> Add(Joint& ioJoint, const Vec3& inPointA, const Vec3& inPointB);

    ConstraintManager& mManager;
    BodyManager& mBodies;
};

} // namespace cairn::physics
