#pragma once

// The ray-sphere quadratic |o + t d|^2 = r^2, i.e. a t^2 + 2 b t + c = 0 with a = d.d, b = o.d and
// c = o.o - r^2, solved so that long rays keep the precision their inputs have (a few float steps of the
// origin's distance): the sphere's and the capsule's ray tests (the cylinder's too, in its plane).
//
// The textbook discriminant b^2 - a c subtracts two numbers of the size of (|o| |d|)^2. For a ray of a few
// km those are about 1e13, whose float steps are larger than the a r^2 they differ by, so a ray passing
// metres beside a half-metre sphere "hit" it. The same value, written a (r^2 - |o - (b / a) d|^2), takes the
// square of the ray line's distance to the centre, which is small, and keeps its precision (after
// "Precision Improvements for Ray/Sphere Intersection", Haines et al., Ray Tracing Gems, 2019).

#include "cairn/physics/math/Math.h"

#include <cmath>

namespace cairn::physics::RayQuadratic
{

/// b^2 - a c, computed as a (r^2 - (the ray line's squared distance to the centre)). inA = d.d > 0.
inline float Discriminant(const Vec3& inOrigin, const Vec3& inDirection, float inA, float inB, float inRadius)
{
    const Vec3 closestToCentre = inOrigin - (inB / inA) * inDirection;
    return inA * (inRadius * inRadius - closestToCentre.squaredNorm());
}

/// The smaller root, the entry, for a ray moving towards the centre (inB < 0) with inDiscriminant >= 0.
/// c / q with q = -b + sqrt(disc): both terms of q are positive, so nothing cancels, also when the origin is
/// near the surface (c near 0), where (-b - sqrt(disc)) / a would.
inline float Entry(float inB, float inC, float inDiscriminant)
{
    return inC / (-inB + std::sqrt(inDiscriminant));
}

} // namespace cairn::physics::RayQuadratic
